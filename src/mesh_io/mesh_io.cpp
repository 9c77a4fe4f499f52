#include "primseg/mesh_io.hpp"

#include "file_io.hpp"

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
  const detail::FileImage image = detail::read_file(path);
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
