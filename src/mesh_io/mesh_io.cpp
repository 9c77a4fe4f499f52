#include "primseg/mesh_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "primseg/error.hpp"
#include "readers.hpp"

namespace primseg {
namespace {

std::string lower_ascii(std::string text) {
  for (char& c : text) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return text;
}

[[noreturn]] void io_failure(const std::filesystem::path& path, std::string_view action,
                             int error_number) {
  throw IoError("cannot " + std::string(action) + " '" + path.string() +
                "': " + std::strerror(error_number));
}

/// The whole file in one block: every reader parses from memory, never through a stream.
struct FileImage {
  std::unique_ptr<char[]> bytes;
  std::size_t size = 0;
};

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

}  // namespace

MeshFormat mesh_format_from_path(const std::filesystem::path& path) {
  const std::string extension = lower_ascii(path.extension().string());
  if (extension == ".off") return MeshFormat::Off;
  if (extension == ".obj") return MeshFormat::Obj;
  if (extension == ".ply") return MeshFormat::Ply;
  if (extension == ".stl") return MeshFormat::Stl;
  throw InvalidInputError("'" + path.string() + "': unknown mesh file extension '" +
                          path.extension().string() + "' (expected .off, .obj, .ply or .stl)");
}

Mesh read_mesh(const std::filesystem::path& path) {
  const MeshFormat format = mesh_format_from_path(path);
  const FileImage image = read_file(path);
  return read_mesh(std::span<const char>(image.bytes.get(), image.size), format, path.string());
}

Mesh read_mesh(std::span<const char> bytes, MeshFormat format, std::string_view name) {
  switch (format) {
    case MeshFormat::Off:
      return mesh_io_detail::read_off(bytes, name);
    case MeshFormat::Obj:
      return mesh_io_detail::read_obj(bytes, name);
    case MeshFormat::Ply:
      return mesh_io_detail::read_ply(bytes, name);
    case MeshFormat::Stl:
      return mesh_io_detail::read_stl(bytes, name);
  }
  throw InvalidInputError(std::string(name) + ": unknown mesh format");
}

namespace mesh_io_detail {

Mesh to_mesh(PolygonSoup&& soup) {
  return Mesh::from_polygons(std::move(soup.positions), std::move(soup.offsets),
                             std::move(soup.vertices));
}

}  // namespace mesh_io_detail
}  // namespace primseg
