#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>

#include "huge_pages.hpp"
#include "readers.hpp"
#include "text_scanner.hpp"

namespace primseg::mesh_io_detail {
namespace {

class ObjReader {
 public:
  ObjReader(std::span<const char> bytes, std::string_view file_name)
      : in_(bytes, file_name, {.line_bounded = true, .comment = '#'}) {}

  Mesh read() {
    if (in_.remaining() == 0) in_.fail_at(in_.cursor(), "file is empty");
    reserve_for_statements();
    while (!in_.at_end()) {
      const std::string_view keyword = in_.read_token();
      if (keyword == "v") {
        read_vertex();
      } else if (keyword == "f") {
        read_face();
      }
      // Everything else (vt, vn, g, o, s, usemtl, mtllib, l, p, ...) does not shape the surface.
      in_.skip_line();
    }
    if (forward_reference_ != nullptr && max_index_ > soup_.positions.size()) {
      in_.fail_at(forward_reference_, "face refers to vertex " + std::to_string(max_index_) +
                                          " but the file has " +
                                          std::to_string(soup_.positions.size()) + " vertices");
    }
    if (soup_.face_count() == 0) {
      in_.fail_at(in_.end(),
                  "mesh has no faces (the file has " + std::to_string(soup_.positions.size()) +
                      " vertices and no 'f' statement)",
                  ErrorKind::InvalidInput);
    }
    return to_mesh(std::move(soup_));
  }

 private:
  // Growing the arrays as statements come costs more than this pass over the line starts.
  void reserve_for_statements() {
    std::size_t vertices = 0;
    std::size_t faces = 0;
    const char* line = in_.begin();
    const char* const end = in_.end();
    while (line != end) {
      while (line != end && is_blank(*line)) ++line;
      if (end - line >= 2 && is_blank(line[1])) {
        vertices += line[0] == 'v';
        faces += line[0] == 'f';
      }
      const void* newline = std::memchr(line, '\n', static_cast<std::size_t>(end - line));
      line = newline == nullptr ? end : static_cast<const char*>(newline) + 1;
    }
    detail::reserve_huge(soup_.positions, vertices);
    detail::reserve_huge(soup_.offsets, faces + 1);
    detail::reserve_huge(soup_.vertices, 3 * faces);
  }

  void read_vertex() {
    Vec3& position = soup_.positions.emplace_back();
    for (double& coordinate : position) {
      if (!in_.read_double(coordinate)) in_.fail_at_token("expected a vertex coordinate");
      if (!std::isfinite(coordinate)) {
        in_.fail_at(in_.last_token(),
                    "vertex " + std::to_string(soup_.positions.size() - 1) +
                        " has a non-finite coordinate " + quote_token(in_.last_token(), in_.end()),
                    ErrorKind::InvalidInput);
      }
    }
    // A 'w' or per-vertex colour may follow; the caller skips the rest of the line.
  }

  // Corners are "v", "v/vt", "v//vn" or "v/vt/vn"; only v matters. Positive indices may point
  // past the vertices read so far (they are checked at the end), negative ones count back from
  // the last vertex read.
  void read_face() {
    const std::size_t first = soup_.vertices.size();
    const char* statement = in_.last_token();
    while (!in_.at_end_of_statement()) {
      const char* corner = in_.cursor();
      std::int64_t index = 0;
      const char* end = parse_integer(corner, in_.end(), index);
      if (end == nullptr || (end != in_.end() && *end != '/' && !in_.is_separator(*end))) {
        in_.fail_at(corner, "expected a vertex index, found " + quote_token(corner, in_.end()));
      }
      const std::size_t vertex_count = soup_.positions.size();
      std::uint64_t resolved = 0;
      if (index > 0) {
        resolved = static_cast<std::uint64_t>(index) - 1;
        if (resolved >= vertex_count) {
          if (resolved >= std::numeric_limits<std::uint32_t>::max()) {
            in_.fail_at(corner, "vertex index " + std::to_string(index) + " is too large");
          }
          if (static_cast<std::uint64_t>(index) > max_index_) {
            max_index_ = static_cast<std::uint64_t>(index);
            forward_reference_ = corner;
          }
        }
      } else if (index < 0) {
        if (static_cast<std::uint64_t>(-(index + 1)) >= vertex_count) {
          in_.fail_at(corner, "relative vertex index " + std::to_string(index) +
                                  " reaches before the first vertex (" +
                                  std::to_string(vertex_count) + " vertices read so far)");
        }
        resolved = vertex_count - static_cast<std::uint64_t>(-(index + 1)) - 1;
      } else {
        in_.fail_at(corner, "vertex index 0 is invalid (OBJ indices start at 1)");
      }
      soup_.vertices.push_back(static_cast<std::uint32_t>(resolved));
      in_.set_cursor(end);
      while (in_.cursor() != in_.end() && !in_.is_separator(*in_.cursor())) {
        in_.set_cursor(in_.cursor() + 1);  // Texture and normal indices.
      }
    }
    const std::size_t size = soup_.vertices.size() - first;
    if (size < 3) {
      in_.fail_at(statement,
                  "face has " + std::to_string(size) + " vertices, at least 3 are needed");
    }
    soup_.end_face();
  }

  TextScanner in_;
  PolygonSoup soup_;
  std::uint64_t max_index_ = 0;
  const char* forward_reference_ = nullptr;
};

}  // namespace

Mesh read_obj(std::span<const char> bytes, std::string_view file_name) {
  return ObjReader(bytes, file_name).read();
}

}  // namespace primseg::mesh_io_detail
