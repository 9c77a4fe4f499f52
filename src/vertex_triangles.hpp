#pragma once
// The triangles around each vertex of a mesh, as compressed rows.

#include <cstdint>
#include <vector>

#include "primseg/mesh.hpp"

namespace primseg {

/// Those of vertex v are triangles[offsets[v] .. offsets[v + 1]), in increasing order.
struct VertexTriangles {
  std::vector<std::uint32_t> offsets;
  std::vector<std::uint32_t> triangles;
};

inline VertexTriangles vertex_triangles(const Mesh& mesh) {
  VertexTriangles rows;
  rows.offsets.assign(mesh.vertex_count() + 1, 0);
  for (const Triangle& t : mesh.triangles)
    for (const std::uint32_t v : t) ++rows.offsets[v + 1];
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) rows.offsets[v + 1] += rows.offsets[v];
  rows.triangles.resize(rows.offsets.back());
  std::vector<std::uint32_t> fill(rows.offsets.begin(), rows.offsets.end() - 1);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t)
    for (const std::uint32_t v : mesh.triangles[t]) rows.triangles[fill[v]++] = t;
  return rows;
}

}  // namespace primseg
