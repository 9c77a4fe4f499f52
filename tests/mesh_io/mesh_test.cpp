// Mesh construction: triangulation of polygons, the input checks and validate().

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <vector>

#include "mesh_io_test_helpers.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh.hpp"

namespace primseg {
namespace {

using mesh_io_test::tetrahedron_positions;
using mesh_io_test::tetrahedron_triangles;

Vec3 triangle_normal(const Mesh& mesh, const Triangle& t) {
  const Vec3& a = mesh.positions[t[0]];
  const Vec3& b = mesh.positions[t[1]];
  const Vec3& c = mesh.positions[t[2]];
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const Vec3 v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {(u[1] * v[2] - u[2] * v[1]) / 2, (u[2] * v[0] - u[0] * v[2]) / 2,
          (u[0] * v[1] - u[1] * v[0]) / 2};
}

double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// Even-odd rule on the xy projection.
bool inside_polygon_xy(const std::vector<Vec3>& loop, double x, double y) {
  bool inside = false;
  for (std::size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    const Vec3& a = loop[i];
    const Vec3& b = loop[j];
    if ((a[1] > y) != (b[1] > y) && x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0]) {
      inside = !inside;
    }
  }
  return inside;
}

/// Checks that the triangles of face 0 tile the planar xy polygon `loop`: right count, same
/// orientation as the polygon (+z), total area equal to the polygon's, every triangle inside.
void expect_tiles_polygon(const std::vector<Vec3>& loop, double polygon_area) {
  std::vector<std::uint32_t> vertices(loop.size());
  for (std::uint32_t i = 0; i < loop.size(); ++i) vertices[i] = i;
  const Mesh mesh =
      Mesh::from_polygons(loop, {0, static_cast<std::uint32_t>(loop.size())}, vertices);
  ASSERT_EQ(mesh.triangle_count(), loop.size() - 2);
  EXPECT_EQ(mesh.face_of_triangle, std::vector<std::uint32_t>(loop.size() - 2, 0));
  double area = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3 normal = triangle_normal(mesh, t);
    EXPECT_GT(normal[2], 0.0) << "triangle " << t[0] << " " << t[1] << " " << t[2];
    area += normal[2];
    // Points strictly inside the triangle must be inside the polygon.
    for (const auto& [wa, wb, wc] : {std::array{1.0, 1.0, 1.0}, std::array{4.0, 1.0, 1.0},
                                     std::array{1.0, 4.0, 1.0}, std::array{1.0, 1.0, 4.0}}) {
      const double w = wa + wb + wc;
      const double x = (wa * loop[t[0]][0] + wb * loop[t[1]][0] + wc * loop[t[2]][0]) / w;
      const double y = (wa * loop[t[0]][1] + wb * loop[t[1]][1] + wc * loop[t[2]][1]) / w;
      EXPECT_TRUE(inside_polygon_xy(loop, x, y)) << "(" << x << ", " << y << ") is outside";
    }
  }
  EXPECT_NEAR(area, polygon_area, 1e-11 * polygon_area);
}

TEST(MeshFromPolygons, ConcaveLShapedHexagonGivesFourTrianglesInsideIt) {
  expect_tiles_polygon({{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}}, 3.0);
  // Same shape starting at the reflex vertex, which a naive fan would get wrong.
  expect_tiles_polygon({{1, 1, 0}, {1, 2, 0}, {0, 2, 0}, {0, 0, 0}, {2, 0, 0}, {2, 1, 0}}, 3.0);
}

TEST(MeshFromPolygons, FlatVerticesNeverMakeDegenerateTriangles) {
  // A square with a vertex in the middle of every side, starting at one of them: clipping a flat
  // vertex would make a triangle of zero area (expect_tiles_polygon wants every area positive).
  expect_tiles_polygon(
      {{1, 0, 0}, {2, 0, 0}, {2, 1, 0}, {2, 2, 0}, {1, 2, 0}, {0, 2, 0}, {0, 1, 0}, {0, 0, 0}},
      4.0);
  // The same with three vertices on one side.
  expect_tiles_polygon(
      {{0.5, 0, 0}, {1, 0, 0}, {1.5, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {0, 0, 0}}, 4.0);
}

TEST(MeshFromPolygons, SquareWithASquareHoleThroughABridgeIsTiled) {
  // One loop: the outer square counter-clockwise, a bridge from the middle of its left side to
  // a corner of the hole, the hole clockwise, and back along the bridge, so each end of the
  // bridge appears twice. At the hole's corner the bridge leaves 45 and 225 degrees: one copy is
  // reflex and lies on a corner of the ears next to the other, which it must not block. The hole
  // stays empty.
  expect_tiles_polygon({{0, 0, 0},
                        {4, 0, 0},
                        {4, 4, 0},
                        {0, 4, 0},
                        {0, 2, 0},
                        {1, 1, 0},
                        {1, 3, 0},
                        {3, 3, 0},
                        {3, 1, 0},
                        {1, 1, 0},
                        {0, 2, 0}},
                       16.0 - 4.0);
}

TEST(MeshFromPolygons, CombWithManyReflexVerticesIsTiled) {
  // A comb: a base strip 0 <= y <= 1 with n teeth up to y = 3 between notches.
  const int teeth = 25;
  std::vector<Vec3> loop{{0, 0, 0}, {2.0 * teeth, 0, 0}};
  for (int i = teeth; i > 0; --i) {
    loop.push_back({2.0 * i, 3, 0});
    loop.push_back({2.0 * i - 1, 3, 0});
    loop.push_back({2.0 * i - 1, 1, 0});
    loop.push_back({2.0 * i - 2, 1, 0});
  }
  // Area: base strip 2n x 1 plus n teeth of 1 x 2.
  expect_tiles_polygon(loop, 2.0 * teeth + 2.0 * teeth);
}

TEST(MeshFromPolygons, LargeStarPolygonIsTiledQuickly) {
  // 2000 spikes: half of the 4000 vertices are reflex.
  const int points = 4000;
  std::vector<Vec3> loop;
  for (int i = 0; i < points; ++i) {
    const double angle = 2 * std::numbers::pi * i / points;
    const double radius = i % 2 == 0 ? 1.0 : 0.9;
    loop.push_back({radius * std::cos(angle), radius * std::sin(angle), 0.0});
  }
  double area = 0.0;  // Shoelace.
  for (int i = 0; i < points; ++i) {
    const Vec3& a = loop[i];
    const Vec3& b = loop[(i + 1) % points];
    area += (a[0] * b[1] - a[1] * b[0]) / 2;
  }
  const auto start = std::chrono::steady_clock::now();
  expect_tiles_polygon(loop, area);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
}

double shoelace_area(const std::vector<Vec3>& loop) {
  double area = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vec3& a = loop[i];
    const Vec3& b = loop[(i + 1) % loop.size()];
    area += (a[0] * b[1] - a[1] * b[0]) / 2;
  }
  return area;
}

/// For polygons too large for expect_tiles_polygon's inside test: loop.size() - 2 triangles, all
/// facing +z, that add up to the polygon's area. Overlapping triangles (a fan of what is left of
/// a polygon) face both ways.
void expect_covers_polygon(const std::vector<Vec3>& loop) {
  const auto n = static_cast<std::uint32_t>(loop.size());
  std::vector<std::uint32_t> vertices(n);
  for (std::uint32_t i = 0; i < n; ++i) vertices[i] = i;
  const Mesh mesh = Mesh::from_polygons(loop, {0, n}, vertices);
  ASSERT_EQ(mesh.triangle_count(), n - 2);
  double area = 0.0;
  std::size_t reversed = 0;
  for (const Triangle& t : mesh.triangles) {
    const double z = triangle_normal(mesh, t)[2];
    reversed += z <= 0.0;
    area += z;
  }
  EXPECT_EQ(reversed, 0u);
  EXPECT_NEAR(area, shoelace_area(loop), 1e-11 * std::abs(shoelace_area(loop)));
}

TEST(MeshFromPolygons, SpiralStripIsTiled) {
  // A strip 0.2 wide between two arms of a spiral whose laps are 0.63 apart, 20,000 vertices,
  // counter-clockwise. The ears along the outer wall grow into fans that the next lap blocks, and
  // the inner wall is reflex, so each lap of the loop clips a few ears: scanning the loop for
  // every ear ran out of budget after 13 s and fanned the rest into overlapping triangles.
  std::vector<Vec3> loop;
  const int per_arm = 10000;
  for (int i = 0; i < per_arm; ++i) {  // out along the outer arm, back along the inner one
    const double angle = 0.05 * i, radius = 1.2 + 0.1 * angle;
    loop.push_back({radius * std::cos(angle), radius * std::sin(angle), 0.0});
  }
  for (int i = per_arm; i-- > 0;) {
    const double angle = 0.05 * i, radius = 1.0 + 0.1 * angle;
    loop.push_back({radius * std::cos(angle), radius * std::sin(angle), 0.0});
  }
  expect_covers_polygon(loop);
}

TEST(MeshFromPolygons, LargePolygonWithAHoleThroughABridgeIsTiled) {
  // A disc of 300 vertices with a hole of 200, joined by a bridge whose two ends appear twice:
  // the grid of reflex vertices holds copies of one point, which must not block each other's ears.
  std::vector<Vec3> loop;
  for (int i = 0; i <= 300; ++i) {
    const double angle = 2 * std::numbers::pi * i / 300;
    loop.push_back({2 * std::cos(angle), 2 * std::sin(angle), 0.0});
  }
  for (int i = 0; i <= 200; ++i) {  // clockwise
    const double angle = -2 * std::numbers::pi * i / 200;
    loop.push_back({1 + 0.5 * std::cos(angle), 0.5 * std::sin(angle), 0.0});
  }
  expect_tiles_polygon(loop, shoelace_area(loop));
}

TEST(MeshFromPolygons, LargeWavyOutlineIsTiled) {
  // 60,000 vertices on seven lobes, a third of them reflex.
  const int n = 60000;
  std::vector<Vec3> loop;
  for (int i = 0; i < n; ++i) {
    const double angle = 2 * std::numbers::pi * i / n, radius = 1 + 0.3 * std::sin(7 * angle);
    loop.push_back({radius * std::cos(angle), radius * std::sin(angle), 0.0});
  }
  expect_covers_polygon(loop);
}

TEST(MeshFromPolygons, TiltedConcavePolygonKeepsItsOrientation) {
  // The L hexagon rotated out of the xy plane, listed clockwise as seen from +n.
  const double c = std::cos(0.7), s = std::sin(0.7);
  std::vector<Vec3> positions;
  for (const auto& [x, y] : {std::array{0.0, 2.0}, std::array{1.0, 2.0}, std::array{1.0, 1.0},
                             std::array{2.0, 1.0}, std::array{2.0, 0.0}, std::array{0.0, 0.0}}) {
    positions.push_back({10 + x, 5 + c * y, s * y});  // Far from the origin on purpose.
  }
  const Mesh mesh = Mesh::from_polygons(positions, {0, 6}, {0, 1, 2, 3, 4, 5});
  ASSERT_EQ(mesh.triangle_count(), 4u);
  const Vec3 polygon_normal{0.0, s, -c};  // Clockwise in the plane: -(plane normal).
  double area = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3 normal = triangle_normal(mesh, t);
    const double along = dot(normal, polygon_normal);
    EXPECT_GT(along, 0.0);
    area += along;
  }
  EXPECT_NEAR(area, 3.0, 1e-12);
}

TEST(MeshFromPolygons, ConvexFacesAndFaceOfTriangle) {
  // A triangle, a quad and a pentagon: 1 + 2 + 3 triangles, in face order.
  const std::vector<Vec3> positions{{0, 0, 0}, {1, 0, 0},   {1, 1, 0},   {0, 1, 0},  {2, 0, 0},
                                    {3, 0, 0}, {3.5, 1, 0}, {2.5, 2, 0}, {1.5, 1, 0}};
  const Mesh mesh =
      Mesh::from_polygons(positions, {0, 3, 7, 12}, {0, 1, 2, 0, 1, 2, 3, 4, 5, 6, 7, 8});
  EXPECT_EQ(mesh.face_count(), 3u);
  EXPECT_EQ(mesh.face_of_triangle, (std::vector<std::uint32_t>{0, 1, 1, 2, 2, 2}));
  EXPECT_EQ(mesh.triangles[0], (Triangle{0, 1, 2}));
  for (const Triangle& t : mesh.triangles) EXPECT_GT(triangle_normal(mesh, t)[2], 0.0);
  EXPECT_NO_THROW(mesh.validate());
}

TEST(MeshFromPolygons, DegenerateAndDuplicateFacesAreKept) {
  const std::vector<Vec3> positions{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {5, 5, 5}};
  // Repeated index, collinear triangle, a duplicate face, a quad with a repeated vertex, and an
  // isolated vertex (4).
  const Mesh mesh = Mesh::from_polygons(positions, {0, 3, 6, 9, 12, 16},
                                        {0, 0, 1, 0, 1, 2, 0, 1, 3, 0, 1, 3, 0, 1, 1, 3});
  EXPECT_EQ(mesh.face_count(), 5u);
  EXPECT_EQ(mesh.triangle_count(), 6u);
  EXPECT_EQ(mesh.vertex_count(), 5u);
  EXPECT_NO_THROW(mesh.validate());
  // Zero-area polygon of more than 3 vertices: still n - 2 triangles.
  const Mesh flat = Mesh::from_polygons(positions, {0, 5}, {0, 1, 2, 1, 0});
  EXPECT_EQ(flat.triangle_count(), 3u);
}

TEST(MeshFromPolygons, LargeConvexPolygonIsFast) {
  const std::uint32_t n = 20000;
  const Mesh mesh = mesh_io_test::regular_polygon(n);
  EXPECT_EQ(mesh.triangle_count(), n - 2);
}

TEST(MeshFromPolygons, RejectsBadInput) {
  const std::vector<Vec3> positions{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  try {
    Mesh::from_polygons({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, NAN, 0}}, {0, 3}, {0, 1, 2});
    FAIL() << "NaN accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_STREQ(error.what(), "vertex 3 has a non-finite coordinate");
  }
  EXPECT_THROW(Mesh::from_polygons({{0, 0, 0}, {1, INFINITY, 0}, {0, 1, 0}}, {0, 3}, {0, 1, 2}),
               InvalidInputError);
  try {
    Mesh::from_polygons(positions, {0, 3}, {0, 1, 7});
    FAIL() << "index out of range accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("vertex 7"), std::string::npos) << error.what();
  }
  EXPECT_THROW(Mesh::from_polygons(positions, {0, 2}, {0, 1}), InvalidInputError);
  EXPECT_THROW(Mesh::from_polygons(positions, {0, 3, 3}, {0, 1, 2}), InvalidInputError);
  EXPECT_THROW(Mesh::from_polygons(positions, {0, 3}, {0, 1, 2, 0}), InvalidInputError);
  EXPECT_THROW(Mesh::from_polygons(positions, {}, {}), InvalidInputError);
  try {
    Mesh::from_polygons(positions, {0}, {});
    FAIL() << "empty mesh accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_STREQ(error.what(), "mesh has no faces");
  }
  EXPECT_THROW(Mesh::from_triangles(positions, {}), InvalidInputError);
  EXPECT_THROW(Mesh::from_triangles(positions, {{0, 1, 3}}), InvalidInputError);
}

TEST(MeshFromTriangles, KeepsTrianglesAsFaces) {
  const Mesh mesh = Mesh::from_triangles(tetrahedron_positions(), tetrahedron_triangles());
  EXPECT_EQ(mesh.face_count(), 4u);
  EXPECT_EQ(mesh.triangles, tetrahedron_triangles());
  EXPECT_EQ(mesh.polygon_offsets, (std::vector<std::uint32_t>{0, 3, 6, 9, 12}));
  EXPECT_EQ(mesh.face_of_triangle, (std::vector<std::uint32_t>{0, 1, 2, 3}));
  EXPECT_NO_THROW(mesh.validate());
}

TEST(MeshValidate, DetectsBrokenInvariants) {
  const Mesh good = Mesh::from_triangles(tetrahedron_positions(), tetrahedron_triangles());
  Mesh mesh = good;
  mesh.positions[1][2] = NAN;
  EXPECT_THROW(mesh.validate(), InvalidInputError);
  mesh = good;
  mesh.triangles[2][1] = 9;
  EXPECT_THROW(mesh.validate(), InvalidInputError);
  mesh = good;
  mesh.face_of_triangle = {0, 2, 2, 3};  // Face 1 has no triangle.
  EXPECT_THROW(mesh.validate(), InvalidInputError);
  mesh = good;
  mesh.face_of_triangle = {0, 1, 2, 2};  // Face 3 has no triangle.
  EXPECT_THROW(mesh.validate(), InvalidInputError);
  mesh = good;
  mesh.face_of_triangle.pop_back();
  EXPECT_THROW(mesh.validate(), InvalidInputError);
  mesh = good;
  mesh.polygon_offsets[2] = 5;  // Face 0 would have 5 vertices, face 1 one.
  EXPECT_THROW(mesh.validate(), InvalidInputError);
  mesh = good;
  mesh.polygon_vertices[4] = 4;
  EXPECT_THROW(mesh.validate(), InvalidInputError);
  EXPECT_THROW(Mesh{}.validate(), InvalidInputError);
}

TEST(BoundingBox, DiagonalAndCentreIgnoreIsolatedVertices) {
  std::vector<Vec3> positions = tetrahedron_positions();
  positions.push_back({100, 100, 100});
  const Mesh mesh = Mesh::from_triangles(positions, tetrahedron_triangles());
  EXPECT_DOUBLE_EQ(bounding_box_diagonal(mesh), std::sqrt(3.0));
  EXPECT_EQ(bounding_box_diagonal(Mesh{}), 0.0);
  EXPECT_EQ(bounding_box_centre(mesh), Vec3({0.5, 0.5, 0.5}));
  EXPECT_EQ(bounding_box_centre(Mesh{}), Vec3({0, 0, 0}));
  // Near the largest doubles, where (low + high) / 2 would overflow.
  const Mesh far =
      Mesh::from_triangles({{1.5e308, 0, 0}, {1.7e308, 0, 0}, {1.6e308, 1, 0}}, {{0, 1, 2}});
  EXPECT_DOUBLE_EQ(bounding_box_centre(far)[0], 1.6e308);
}

}  // namespace
}  // namespace primseg
