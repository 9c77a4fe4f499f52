#include "file_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>

#include "primseg/error.hpp"

namespace primseg::detail {

[[noreturn]] void io_failure(const std::filesystem::path& path, std::string_view action,
                             int error_number) {
  throw IoError("cannot " + std::string(action) + " '" + path.string() +
                "': " + std::strerror(error_number));
}

FileImage read_file(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) io_failure(path, "open", errno);
  struct FdCloser {
    int fd;
    ~FdCloser() { ::close(fd); }
  } closer{fd};

  struct stat status {};
  if (::fstat(fd, &status) != 0) io_failure(path, "stat", errno);
  if (S_ISDIR(status.st_mode)) io_failure(path, "read", EISDIR);

  // The size from fstat may be stale (a growing file): read until end of file regardless.
  std::size_t capacity = static_cast<std::size_t>(status.st_size) + 1;
  FileImage image{std::make_unique_for_overwrite<char[]>(capacity), 0};
  while (true) {
    if (image.size == capacity) {
      const std::size_t grown = capacity + capacity / 2 + 4096;
      auto larger = std::make_unique_for_overwrite<char[]>(grown);
      std::memcpy(larger.get(), image.bytes.get(), image.size);
      image.bytes = std::move(larger);
      capacity = grown;
    }
    const ssize_t got = ::read(fd, image.bytes.get() + image.size, capacity - image.size);
    if (got < 0) {
      if (errno == EINTR) continue;
      io_failure(path, "read", errno);
    }
    if (got == 0) return image;
    image.size += static_cast<std::size_t>(got);
  }
}

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes) {
  static std::atomic<unsigned> counter{0};
  std::filesystem::path temporary = path;
  // Appended piecewise: `"." + string` trips a false -Wrestrict in g++ 12 release builds.
  std::string name(1, '.');
  name.append(path.filename().string())
      .append(".tmp")
      .append(std::to_string(::getpid()))
      .append("_")
      .append(std::to_string(counter++));
  temporary.replace_filename(name);
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) io_failure(path, "create a temporary file for", errno);
  const auto abandon = [&](std::string_view action) {
    const int error_number = errno;
    ::close(fd);
    ::unlink(temporary.c_str());
    io_failure(path, action, error_number);
  };
  std::size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t result = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (result < 0) {
      if (errno == EINTR) continue;
      abandon("write");
    }
    written += static_cast<std::size_t>(result);
  }
  if (::fsync(fd) != 0) abandon("flush");
  if (::close(fd) != 0) {
    const int error_number = errno;
    ::unlink(temporary.c_str());
    io_failure(path, "write", error_number);
  }
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error_number = errno;
    ::unlink(temporary.c_str());
    io_failure(path, "rename a temporary file onto", error_number);
  }
}

}  // namespace primseg::detail
