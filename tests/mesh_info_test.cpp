// What `primseg info` counts (mesh_info.hpp), here the orientation: edges whose two triangles
// are listed the same way along them, and closed components listed inside out.

#include "primseg/mesh_info.hpp"

#include <gtest/gtest.h>

#include <utility>

#include "primseg/shape_generator.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

Mesh box() {
  ShapeOptions options;
  options.edge_length = 0.25;
  return make_shape("box", options).mesh;
}

void flip(Mesh& mesh, std::uint32_t t) {
  std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
}

// `mesh` and, beside it, `other` moved by `offset` along x: two components.
Mesh with_copy(const Mesh& mesh, const Mesh& other, double offset) {
  std::vector<Vec3> positions = mesh.positions;
  std::vector<Triangle> triangles = mesh.triangles;
  const auto base = static_cast<std::uint32_t>(positions.size());
  for (Vec3 p : other.positions) {
    p[0] += offset;
    positions.push_back(p);
  }
  for (Triangle t : other.triangles) {
    for (std::uint32_t& v : t) v += base;
    triangles.push_back(t);
  }
  return Mesh::from_triangles(std::move(positions), std::move(triangles));
}

TEST(MeshInfo, AnOutwardClosedBoxIsConsistent) {
  const MeshInfo info = describe_mesh(box());
  EXPECT_EQ(info.boundary_edges, 0u);
  EXPECT_EQ(info.inconsistent_edges, 0u);
  EXPECT_EQ(info.inward_components, 0u);
}

TEST(MeshInfo, OneTriangleListedTheOtherWayDisagreesAcrossItsThreeEdges) {
  Mesh mesh = box();
  flip(mesh, 5);
  const MeshInfo info = describe_mesh(mesh);
  EXPECT_EQ(info.inconsistent_edges, 3u);
  EXPECT_EQ(info.inward_components, 0u);  // not consistent, so neither inward nor outward
}

TEST(MeshInfo, ABoxListedInsideOutIsOneInwardComponent) {
  Mesh inward = box();
  for (std::uint32_t t = 0; t < inward.triangle_count(); ++t) flip(inward, t);
  MeshInfo info = describe_mesh(inward);
  EXPECT_EQ(info.inconsistent_edges, 0u);
  EXPECT_EQ(info.inward_components, 1u);
  // Beside an outward copy, far from the origin: one of the two components.
  info = describe_mesh(with_copy(inward, box(), 1e6));
  EXPECT_EQ(info.components, 2u);
  EXPECT_EQ(info.inward_components, 1u);
  info = describe_mesh(with_copy(inward, inward, 3));
  EXPECT_EQ(info.inward_components, 2u);
}

TEST(MeshInfo, AnOpenSheetHasNoInsideButCanDisagree) {
  Mesh sheet = testing::grid_mesh(3, 3, [](double u, double v) { return Vec3{u, v, 0}; });
  MeshInfo info = describe_mesh(sheet);
  EXPECT_GT(info.boundary_edges, 0u);
  EXPECT_EQ(info.inconsistent_edges, 0u);
  for (std::uint32_t t = 0; t < sheet.triangle_count(); ++t) flip(sheet, t);
  EXPECT_EQ(describe_mesh(sheet).inconsistent_edges, 0u);  // flipped whole: still consistent
  flip(sheet, 0);  // a corner triangle: one edge inside the sheet, two on its border
  info = describe_mesh(sheet);
  EXPECT_EQ(info.inconsistent_edges, 1u);
  EXPECT_EQ(info.inward_components, 0u);
}

}  // namespace
}  // namespace primseg
