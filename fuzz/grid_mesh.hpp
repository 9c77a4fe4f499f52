// The small meshes the engine fuzzers decode from their input: vertices on a coarse integer grid,
// so that coplanar, cocircular, degenerate and duplicate configurations are common.
//
// Layout: byte 0 = vertex count − 3 (mod 29), then 3 bytes per vertex (a coordinate in -8..7 from
// each byte), then 3 bytes per triangle (vertex indices mod the vertex count), at most 48
// triangles. Triangles that repeat a vertex are skipped.

#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "primseg/mesh.hpp"

namespace primseg::fuzz {

/// The mesh the bytes describe, each coordinate times `scale`; nullopt when they describe none.
inline std::optional<Mesh> decode_grid_mesh(const std::uint8_t* data, std::size_t size,
                                            double scale = 1) {
  if (size < 1) return std::nullopt;
  const std::size_t vertex_count = 3 + data[0] % 29;
  if (size < 1 + 3 * vertex_count) return std::nullopt;
  std::vector<Vec3> positions(vertex_count);
  const std::uint8_t* in = data + 1;
  for (Vec3& p : positions)
    for (double& c : p) c = (static_cast<double>(*in++ % 16) - 8.0) * scale;
  std::vector<Triangle> triangles;
  for (; in + 3 <= data + size && triangles.size() < 48; in += 3) {
    const Triangle t{static_cast<std::uint32_t>(in[0] % vertex_count),
                     static_cast<std::uint32_t>(in[1] % vertex_count),
                     static_cast<std::uint32_t>(in[2] % vertex_count)};
    if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) triangles.push_back(t);
  }
  if (triangles.empty()) return std::nullopt;
  return Mesh::from_triangles(std::move(positions), std::move(triangles));
}

}  // namespace primseg::fuzz
