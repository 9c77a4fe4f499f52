#include "primseg/mesh_info.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "primseg/dual_graph.hpp"

namespace primseg {

MeshInfo describe_mesh(const Mesh& mesh) {
  MeshInfo info;
  info.vertices = mesh.vertex_count();
  info.faces = mesh.face_count();
  info.triangles = mesh.triangle_count();
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f) info.polygons += mesh.polygon(f).size() > 3;

  const DualGraph graph(mesh, VertexWeights::Area);
  info.components = graph.component_count();

  std::vector<std::array<std::uint32_t, 2>> edges;
  std::vector<std::array<std::uint32_t, 3>> sorted_triangles;
  std::vector<std::uint8_t> used(mesh.vertex_count(), 0);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int c = 0; c < 3; ++c) {
      used[tri[c]] = 1;
      const std::uint32_t a = tri[c], b = tri[(c + 1) % 3];
      if (a != b) edges.push_back({std::min(a, b), std::max(a, b)});
    }
    if (!(graph.triangle_area(t) > 0)) ++info.degenerate_triangles;
    std::array<std::uint32_t, 3> key = tri;
    std::sort(key.begin(), key.end());
    sorted_triangles.push_back(key);
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t begin = 0; begin < edges.size();) {
    std::size_t end = begin;
    while (end < edges.size() && edges[end] == edges[begin]) ++end;
    if (end - begin == 1) ++info.boundary_edges;
    if (end - begin >= 3) ++info.non_manifold_edges;
    begin = end;
  }
  std::sort(sorted_triangles.begin(), sorted_triangles.end());
  for (std::size_t t = 1; t < sorted_triangles.size(); ++t)
    info.duplicate_triangles += sorted_triangles[t] == sorted_triangles[t - 1];
  info.isolated_vertices =
      static_cast<std::uint32_t>(std::count(used.begin(), used.end(), std::uint8_t{0}));

  bool first = true;
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    if (!used[v]) continue;
    for (int a = 0; a < 3; ++a) {
      info.bbox_min[a] =
          first ? mesh.positions[v][a] : std::min(info.bbox_min[a], mesh.positions[v][a]);
      info.bbox_max[a] =
          first ? mesh.positions[v][a] : std::max(info.bbox_max[a], mesh.positions[v][a]);
    }
    first = false;
  }
  info.bbox_diagonal = bounding_box_diagonal(mesh);
  return info;
}

}  // namespace primseg
