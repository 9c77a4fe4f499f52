#include "atomic_write.hpp"

#include <unistd.h>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>

#include "primseg/error.hpp"

namespace primseg::detail {

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes) {
  const std::filesystem::path temp =
      path.string() + ".tmp-" + std::to_string(::getpid()) + "-" +
      std::to_string(reinterpret_cast<std::uintptr_t>(&bytes) & 0xffff);
  std::FILE* file = std::fopen(temp.c_str(), "wb");
  if (!file) throw IoError("cannot write " + path.string() + ": " + std::strerror(errno));
  const bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
  const int saved_errno = errno;
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed) {
    std::remove(temp.c_str());
    throw IoError("cannot write " + path.string() + ": " + std::strerror(saved_errno));
  }
  std::error_code error;
  std::filesystem::rename(temp, path, error);
  if (error) {
    std::remove(temp.c_str());
    throw IoError("cannot write " + path.string() + ": " + error.message());
  }
}

}  // namespace primseg::detail
