#pragma once
// Private: the per-format readers behind primseg::read_mesh. Each takes the whole file image and
// the name to use in error messages.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "primseg/mesh.hpp"

namespace primseg::mesh_io_detail {

Mesh read_off(std::span<const char> bytes, std::string_view file_name);
Mesh read_obj(std::span<const char> bytes, std::string_view file_name);
Mesh read_ply(std::span<const char> bytes, std::string_view file_name);
Mesh read_stl(std::span<const char> bytes, std::string_view file_name);

/// What a reader collects before Mesh::from_polygons triangulates it.
struct PolygonSoup {
  std::vector<Vec3> positions;
  std::vector<std::uint32_t> offsets{0};
  std::vector<std::uint32_t> vertices;

  std::size_t face_count() const { return offsets.size() - 1; }
  /// Closes the face whose vertices were appended since the last call.
  void end_face() { offsets.push_back(static_cast<std::uint32_t>(vertices.size())); }
};

/// Mesh::from_polygons on the soup (the readers have already checked what it checks, with file
/// locations).
Mesh to_mesh(PolygonSoup&& soup);

}  // namespace primseg::mesh_io_detail
