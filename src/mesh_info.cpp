#include "primseg/mesh_info.hpp"

#include <Eigen/Geometry>
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

  // Each triangle side: its edge (lower vertex first), whether the triangle runs along it from
  // the lower vertex, and the triangle.
  struct Side {
    std::uint32_t low, high;
    bool upward;
    std::uint32_t triangle;
  };
  std::vector<Side> sides;
  sides.reserve(3 * std::size_t{mesh.triangle_count()});
  std::vector<std::array<std::uint32_t, 3>> sorted_triangles;
  std::vector<std::uint8_t> used(mesh.vertex_count(), 0);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int c = 0; c < 3; ++c) {
      used[tri[c]] = 1;
      const std::uint32_t a = tri[c], b = tri[(c + 1) % 3];
      if (a != b) sides.push_back({std::min(a, b), std::max(a, b), a < b, t});
    }
    if (!(graph.triangle_area(t) > 0)) ++info.degenerate_triangles;
    std::array<std::uint32_t, 3> key = tri;
    std::sort(key.begin(), key.end());
    sorted_triangles.push_back(key);
  }
  std::sort(sides.begin(), sides.end(), [](const Side& a, const Side& b) {
    return a.low != b.low ? a.low < b.low : a.high < b.high;
  });
  // A component is closed when its every edge has two triangles, and counts as inward only when
  // those run along each edge both ways.
  const std::vector<std::uint32_t>& component_of_face = graph.component_of_face();
  const auto component = [&](std::uint32_t t) {
    return component_of_face[mesh.face_of_triangle[t]];
  };
  std::vector<std::uint8_t> closed_and_consistent(info.components, 1);
  for (std::size_t begin = 0; begin < sides.size();) {
    std::size_t end = begin;
    while (end < sides.size() && sides[end].low == sides[begin].low &&
           sides[end].high == sides[begin].high)
      ++end;
    if (end - begin == 1) ++info.boundary_edges;
    if (end - begin >= 3) ++info.non_manifold_edges;
    const bool inconsistent = end - begin == 2 && sides[begin].upward == sides[begin + 1].upward;
    info.inconsistent_edges += inconsistent;
    if (end - begin != 2 || inconsistent)
      for (std::size_t i = begin; i < end; ++i)
        closed_and_consistent[component(sides[i].triangle)] = 0;
    begin = end;
  }
  // Signed volumes about the bounding box's centre, as the triangles are listed.
  const Vec3 centre = bounding_box_centre(mesh);
  std::vector<double> volume(info.components, 0.0);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    std::array<Eigen::Vector3d, 3> p;
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a) p[c][a] = mesh.positions[mesh.triangles[t][c]][a] - centre[a];
    volume[component(t)] += p[0].dot(p[1].cross(p[2]));
  }
  for (std::uint32_t c = 0; c < info.components; ++c)
    info.inward_components += closed_and_consistent[c] && volume[c] < 0;
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
