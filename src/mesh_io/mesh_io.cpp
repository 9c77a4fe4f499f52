#include "primseg/mesh_io.hpp"

#include "file_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
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

namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

/// The first whitespace-separated token of the text, skipping lines whose first token starts
/// with '#' (comments of OFF and OBJ). Looks at the first kMeshSignatureBytes only.
std::string_view first_token(std::string_view text) {
  text = text.substr(0, std::min(text.size(), kMeshSignatureBytes));
  std::size_t at = 0;
  while (at < text.size()) {
    while (at < text.size() && is_space(text[at])) ++at;
    if (at < text.size() && text[at] == '#') {
      const std::size_t end_of_line = text.find('\n', at);
      at = end_of_line == std::string_view::npos ? text.size() : end_of_line + 1;
      continue;
    }
    std::size_t end = at;
    while (end < text.size() && !is_space(text[end])) ++end;
    return text.substr(at, end - at);
  }
  return {};
}

bool starts_with_ignoring_case(std::string_view text, std::string_view prefix) {
  if (text.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    char c = text[i];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c != prefix[i]) return false;
  }
  return true;
}

// The size of the binary STL whose header `text` would be (an 80-byte header, a little-endian
// triangle count, 50 bytes per triangle); none before the count.
std::optional<std::uint64_t> binary_stl_size(std::string_view text) {
  if (text.size() < 84) return std::nullopt;
  std::uint32_t count = 0;
  for (int i = 3; i >= 0; --i)
    count = count << 8 | static_cast<unsigned char>(text[80 + static_cast<std::size_t>(i)]);
  return 84 + 50 * static_cast<std::uint64_t>(count);
}

// The format named by the start of the text (every signature but binary STL's, which is its size).
std::optional<MeshFormat> text_signature(std::string_view text) {
  if (text.starts_with("ply\n") || text.starts_with("ply\r")) return MeshFormat::Ply;
  if (starts_with_ignoring_case(text, "solid")) return MeshFormat::Stl;
  const std::string_view token = first_token(text);
  if (token.size() >= 3 && token.ends_with("OFF")) return MeshFormat::Off;
  static constexpr std::string_view kObjStatements[] = {"v", "vt", "vn", "vp",     "f",     "o",
                                                        "g", "s",  "l",  "mtllib", "usemtl"};
  for (const std::string_view statement : kObjStatements)
    if (token == statement) return MeshFormat::Obj;
  return std::nullopt;
}

}  // namespace

std::optional<MeshFormat> detect_mesh_format(std::span<const char> bytes) {
  const std::string_view text(bytes.data(), bytes.size());
  const std::optional<MeshFormat> signature = text_signature(text);
  if (signature == MeshFormat::Ply) return signature;
  // Before "solid": the header of a binary STL may start with that word too.
  if (binary_stl_size(text) == text.size()) return MeshFormat::Stl;
  return signature;
}

bool mesh_format_ruled_out(std::span<const char> prefix, std::uint64_t max_size) {
  const std::string_view text(prefix.data(), prefix.size());
  // Past the bytes text signatures are read from, only a binary STL could still be detected, and
  // only if the data can still end at the size its header declares.
  if (text.size() < kMeshSignatureBytes || text_signature(text)) return false;
  const std::optional<std::uint64_t> stl_size = binary_stl_size(text);
  return !(stl_size >= text.size() && stl_size <= max_size);
}

Mesh read_mesh_detecting_format(std::span<const char> bytes, std::string_view name) {
  if (bytes.empty()) throw ParseError(std::string(name) + ": empty, no mesh data");
  const std::optional<MeshFormat> format = detect_mesh_format(bytes);
  if (!format)
    throw ParseError(std::string(name) +
                     ": not a mesh file primseg can read (no OFF, OBJ, PLY or STL signature)");
  return read_mesh(bytes, *format, name);
}

namespace mesh_io_detail {

Mesh to_mesh(PolygonSoup&& soup) {
  return Mesh::from_polygons(std::move(soup.positions), std::move(soup.offsets),
                             std::move(soup.vertices));
}

}  // namespace mesh_io_detail
}  // namespace primseg
