// Cluster borders on generated solids with known regions (a box's 12 edges at 90 degrees, a
// capped cylinder's two circles, a chamfer at 45 degrees, a fillet tangent to its neighbours), on
// open and non-manifold meshes and mixed orientations, and, on fandisk, against a brute-force
// list of every border's edges.

#include "primseg/borders.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using Edge = std::pair<std::uint32_t, std::uint32_t>;

Edge edge(std::uint32_t a, std::uint32_t b) {
  return {std::min(a, b), std::max(a, b)};
}

// Each border's edges, found by brute force: for every mesh edge, its triangles in index order;
// each pair of consecutive distinct triangles of different clusters is a link of the dual graph.
std::map<Edge, std::set<Edge>> expected_border_edges(const Mesh& mesh,
                                                     const std::vector<std::uint32_t>& labels) {
  std::map<Edge, std::vector<std::uint32_t>> triangles_on;  // in increasing order
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t)
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t a = mesh.triangles[t][i], b = mesh.triangles[t][(i + 1) % 3];
      if (a != b) triangles_on[edge(a, b)].push_back(t);
    }
  const auto label = [&](std::uint32_t t) { return labels[mesh.face_of_triangle[t]]; };
  std::map<Edge, std::set<Edge>> borders;
  for (const auto& [e, triangles] : triangles_on) {
    if (triangles.size() == 1) borders[{label(triangles[0]), kMeshBoundary}].insert(e);
    for (std::size_t i = 0; i + 1 < triangles.size(); ++i)
      if (label(triangles[i]) != label(triangles[i + 1]))
        borders[edge(label(triangles[i]), label(triangles[i + 1]))].insert(e);
  }
  return borders;
}

// The borders are the brute-force ones, and each border's curves use each of its edges once.
void expect_curves_cover_the_borders(const Mesh& mesh, const std::vector<std::uint32_t>& labels,
                                     const std::vector<ClusterBorder>& borders) {
  const auto expected = expected_border_edges(mesh, labels);
  ASSERT_EQ(borders.size(), expected.size());
  auto next = expected.begin();
  for (const ClusterBorder& border : borders) {
    SCOPED_TRACE("border " + std::to_string(border.first) + "-" + std::to_string(border.second));
    ASSERT_EQ(Edge(border.first, border.second), next->first);
    std::multiset<Edge> walked;
    double length = 0;
    for (const BorderCurve& curve : border.curves) {
      const auto& v = curve.vertices;
      ASSERT_GE(v.size(), 2u);
      for (std::size_t i = 0; i + 1 < v.size(); ++i) walked.insert(edge(v[i], v[i + 1]));
      if (curve.closed) walked.insert(edge(v.back(), v.front()));
    }
    for (const Edge& e : walked)
      length += std::sqrt(std::pow(mesh.positions[e.first][0] - mesh.positions[e.second][0], 2) +
                          std::pow(mesh.positions[e.first][1] - mesh.positions[e.second][1], 2) +
                          std::pow(mesh.positions[e.first][2] - mesh.positions[e.second][2], 2));
    EXPECT_EQ(walked, std::multiset<Edge>(next->second.begin(), next->second.end()));
    EXPECT_EQ(border.edge_count, next->second.size());
    EXPECT_NEAR(border.length, length, 1e-12 * std::max(1.0, length));
    ++next;
  }
}

GroundTruthShape cad_shape(const std::string& name, bool random_motion = false) {
  ShapeOptions options;
  options.random_motion = random_motion;
  options.seed = 11;
  return make_shape(name, options);
}

using testing::distance;

TEST(ClusterBorders, ABoxHasTwelveStraightEdgesAtRightAngles) {
  for (const bool moved : {false, true}) {
    SCOPED_TRACE(moved ? "moved" : "in place");
    const GroundTruthShape box = cad_shape("box", moved);
    const auto borders = cluster_borders(box.mesh, box.region_of_face, box.regions);
    expect_curves_cover_the_borders(box.mesh, box.region_of_face, borders);
    ASSERT_EQ(borders.size(), 12u);
    std::map<std::uint32_t, int> corner_uses;
    for (const ClusterBorder& border : borders) {
      EXPECT_NEAR(border.angle, 90, 1e-9);
      ASSERT_EQ(border.curves.size(), 1u);
      const BorderCurve& curve = border.curves[0];
      EXPECT_FALSE(curve.closed);
      EXPECT_LT(curve.vertices.front(), curve.vertices.back());
      // A straight edge from corner to corner.
      EXPECT_NEAR(border.length,
                  distance(box.mesh.positions[curve.vertices.front()],
                           box.mesh.positions[curve.vertices.back()]),
                  1e-12 * border.length);
      ++corner_uses[curve.vertices.front()];
      ++corner_uses[curve.vertices.back()];
    }
    ASSERT_EQ(corner_uses.size(), 8u);  // each corner ends three edges
    for (const auto& [corner, uses] : corner_uses) EXPECT_EQ(uses, 3);
  }
}

TEST(ClusterBorders, ACappedCylinderHasTwoClosedCircles) {
  const GroundTruthShape shape = cad_shape("capped_cylinder");
  const auto borders = cluster_borders(shape.mesh, shape.region_of_face, shape.regions);
  expect_curves_cover_the_borders(shape.mesh, shape.region_of_face, borders);
  ASSERT_EQ(borders.size(), 2u);
  double radius = 0;
  for (const Primitive& p : shape.regions)
    if (p.type == PrimitiveType::Cylinder) radius = p.radius;
  const int segments = ShapeOptions{}.segments;
  for (const ClusterBorder& border : borders) {
    EXPECT_NEAR(border.angle, 90, 1e-9);
    ASSERT_EQ(border.curves.size(), 1u);
    EXPECT_TRUE(border.curves[0].closed);
    EXPECT_EQ(border.curves[0].vertices.size(), static_cast<std::size_t>(segments));
    EXPECT_NEAR(border.length, 2 * segments * radius * std::sin(std::numbers::pi / segments),
                1e-12);
  }
}

// The angle tells a chamfer (45 degrees) and a fillet (tangent: 0) from a sharp edge.
TEST(ClusterBorders, ChamfersAndFilletsByTheirAngle) {
  const auto angles_by_types = [](const std::string& name) {
    const GroundTruthShape shape = cad_shape(name, true);
    const auto borders = cluster_borders(shape.mesh, shape.region_of_face, shape.regions);
    expect_curves_cover_the_borders(shape.mesh, shape.region_of_face, borders);
    std::map<std::pair<PrimitiveType, PrimitiveType>, std::vector<double>> angles;
    for (const ClusterBorder& border : borders) {
      auto types = std::minmax(shape.regions[border.first].type, shape.regions[border.second].type);
      angles[types].push_back(border.angle);
    }
    return angles;
  };
  using enum PrimitiveType;
  const auto chamfered = angles_by_types("chamfered_cylinder");
  ASSERT_EQ(chamfered.at({Plane, Cone}).size(), 1u);
  EXPECT_NEAR(chamfered.at({Plane, Cone})[0], 45, 1e-9);
  EXPECT_NEAR(chamfered.at({Cylinder, Cone})[0], 45, 1e-9);
  EXPECT_NEAR(chamfered.at({Plane, Cylinder})[0], 90, 1e-9);

  const auto filleted = angles_by_types("filleted_cylinder");
  // Tangent up to the chords: an edge's midpoint is off the circle where the surfaces touch.
  EXPECT_LT(filleted.at({Plane, Torus})[0], 1);
  EXPECT_LT(filleted.at({Cylinder, Torus})[0], 1);
  EXPECT_NEAR(filleted.at({Plane, Cylinder})[0], 90, 1e-9);

  const auto hole = angles_by_types("box_with_hole");
  ASSERT_EQ(hole.at({Plane, Cylinder}).size(),
            2u);  // a concave cylinder, through the top and bottom
  for (const double angle : hole.at({Plane, Cylinder})) EXPECT_NEAR(angle, 90, 1e-9);
}

// How the file orients its faces changes nothing: the tetrahedron with two faces listed inwards
// has the angles between its outward normals.
TEST(ClusterBorders, AnglesDoNotDependOnTheFacesOrientation) {
  const testing::TetrahedronWithInwardFaces tetrahedron;
  const Mesh& mesh = tetrahedron.mesh;
  const std::vector<std::uint32_t> labels{0, 1, 2, 3};
  std::vector<Primitive> planes(4);
  std::vector<Vec3> outward(4);
  for (std::uint32_t f = 0; f < 4; ++f) {
    const Triangle& t = mesh.triangles[f];
    const Vec3& a = mesh.positions[t[0]];
    const Vec3& b = mesh.positions[t[1]];
    const Vec3& c = mesh.positions[t[2]];
    const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    Vec3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double length = std::hypot(n[0], n[1], n[2]);
    for (double& x : n) x /= length;
    // The corner not on face f is behind the outward normal.
    std::uint32_t opposite = 0;
    while (std::count(t.begin(), t.end(), opposite)) ++opposite;
    const Vec3& o = mesh.positions[opposite];
    const double side = n[0] * (o[0] - a[0]) + n[1] * (o[1] - a[1]) + n[2] * (o[2] - a[2]);
    outward[f] = side < 0 ? n : Vec3{-n[0], -n[1], -n[2]};
    planes[f].point = a;
    planes[f].axis = f % 2 ? outward[f] : Vec3{-outward[f][0], -outward[f][1], -outward[f][2]};
  }
  const auto borders = cluster_borders(mesh, labels, planes);
  expect_curves_cover_the_borders(mesh, labels, borders);
  ASSERT_EQ(borders.size(), 6u);
  for (const ClusterBorder& border : borders) {
    const Vec3& a = outward[border.first];
    const Vec3& b = outward[border.second];
    const double expected =
        std::acos(std::clamp(a[0] * b[0] + a[1] * b[1] + a[2] * b[2], -1.0, 1.0)) * 180 /
        std::numbers::pi;
    EXPECT_NEAR(border.angle, expected, 1e-9);
  }
}

// A sheet folded flat onto itself turns by 180 degrees, not a rounding error more.
TEST(ClusterBorders, AFoldedSheetIsAtOneHundredAndEightyDegrees) {
  const Mesh folded = Mesh::from_triangles({{0, 0, 0}, {1, 0, 0}, {0.5, 0.8, 0}, {0.5, 1, 0}},
                                           {{0, 1, 2}, {1, 0, 3}});
  Primitive plane;
  plane.axis = {0, 0, 1};
  const std::vector<Primitive> planes{plane, plane};
  const auto borders = cluster_borders(folded, std::vector<std::uint32_t>{0, 1}, planes);
  ASSERT_EQ(borders[0].second, 1u);
  EXPECT_EQ(borders[0].angle, 180);
}

// A square sheet in two halves: their border is the middle line, and each half's part of the
// sheet's outline ends where the middle line meets it.
TEST(ClusterBorders, OpenBoundaryCurvesEndWhereABorderMeetsThem) {
  const Mesh sheet = testing::grid_mesh(4, 4, [](double u, double v) { return Vec3{u, v, 0}; });
  std::vector<std::uint32_t> labels(sheet.face_count());
  for (std::uint32_t f = 0; f < sheet.face_count(); ++f) {
    const Triangle& t = sheet.triangles[f];
    double u = 0;
    for (const std::uint32_t v : t) u += sheet.positions[v][0] / 3;
    labels[f] = u < 0.5 ? 0 : 1;
  }
  Primitive up, down;
  up.axis = {0, 0, 1};
  down.axis = {0, 0, -1};
  const std::vector<Primitive> planes{up, down};
  const auto borders = cluster_borders(sheet, labels, planes);
  expect_curves_cover_the_borders(sheet, labels, borders);
  ASSERT_EQ(borders.size(), 3u);
  EXPECT_EQ(borders[0].second, 1u);
  EXPECT_NEAR(borders[0].angle, 0, 1e-12);
  EXPECT_NEAR(borders[0].length, 1, 1e-12);
  for (const std::size_t b : {1, 2}) {
    EXPECT_EQ(borders[b].second, kMeshBoundary);
    EXPECT_TRUE(std::isnan(borders[b].angle));
    EXPECT_NEAR(borders[b].length, 2, 1e-12);
    ASSERT_EQ(borders[b].curves.size(), 1u);
    EXPECT_FALSE(borders[b].curves[0].closed);
    // It ends on the middle line, at both ends.
    const auto& v = borders[b].curves[0].vertices;
    EXPECT_NEAR(sheet.positions[v.front()][0], 0.5, 1e-12);
    EXPECT_NEAR(sheet.positions[v.back()][0], 0.5, 1e-12);
  }

  // One cluster: the outline alone, a closed loop; without primitives, no angle.
  const std::vector<std::uint32_t> one(sheet.face_count(), 0);
  const auto outline = cluster_borders(sheet, one);
  ASSERT_EQ(outline.size(), 1u);
  ASSERT_EQ(outline[0].curves.size(), 1u);
  EXPECT_TRUE(outline[0].curves[0].closed);
  EXPECT_EQ(outline[0].curves[0].vertices.size(), 16u);
  EXPECT_NEAR(outline[0].length, 4, 1e-12);

  // A closed surface in one cluster has no border.
  const GroundTruthShape sphere = cad_shape("sphere");
  EXPECT_TRUE(cluster_borders(sphere.mesh, std::vector<std::uint32_t>(sphere.mesh.face_count(), 0))
                  .empty());
}

// Three triangles on one edge: two clusters share it when the dual graph links a triangle of each
// (the triangles in index order, each linked to the next), as the hierarchy sees them.
TEST(ClusterBorders, NonManifoldEdgesJoinTheClustersTheDualGraphLinks) {
  const Mesh fins = Mesh::from_triangles({{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}},
                                         {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  const auto pairs = [&fins](const std::vector<std::uint32_t>& labels) {
    const auto borders = cluster_borders(fins, labels);
    expect_curves_cover_the_borders(fins, labels, borders);
    std::set<Edge> shared;
    for (const ClusterBorder& border : borders)
      if (border.second != kMeshBoundary) {
        EXPECT_EQ(border.edge_count, 1u);
        shared.insert({border.first, border.second});
      }
    return shared;
  };
  EXPECT_EQ(pairs({0, 1, 2}), (std::set<Edge>{{0, 1}, {1, 2}}));  // not 0-2: t0 and t2 not linked
  EXPECT_EQ(pairs({1, 0, 2}), (std::set<Edge>{{0, 1}, {0, 2}}));
  EXPECT_EQ(pairs({0, 1, 0}), (std::set<Edge>{{0, 1}}));  // two links, one border edge
  EXPECT_EQ(pairs({0, 0, 1}), (std::set<Edge>{{0, 1}}));
  EXPECT_TRUE(pairs({0, 0, 0}).empty());
}

// One cluster: its outline is the N paths from one spine end round a page to the other; the
// spine vertices are on N outline edges each, and each is looked up once per edge (a linear scan
// per lookup made a 100,000-page book take 14 s).
TEST(ClusterBorders, ABookInOneClusterHasOneOutlinePathPerPage) {
  constexpr std::uint32_t kPages = 20000;
  const Mesh pages = testing::book(kPages);
  const std::vector<std::uint32_t> labels(kPages, 0);
  const auto borders = cluster_borders(pages, labels);
  ASSERT_EQ(borders.size(), 1u);
  EXPECT_EQ(borders[0].second, kMeshBoundary);
  EXPECT_EQ(borders[0].edge_count, 2 * kPages);
  ASSERT_EQ(borders[0].curves.size(), kPages);
  std::set<std::uint32_t> rims;
  for (const BorderCurve& curve : borders[0].curves) {
    ASSERT_EQ(curve.vertices.size(), 3u);
    EXPECT_FALSE(curve.closed);
    EXPECT_EQ(curve.vertices[0], 0u);
    EXPECT_EQ(curve.vertices[2], 1u);
    rims.insert(curve.vertices[1]);
  }
  EXPECT_EQ(rims.size(), kPages);
}

// One cluster per page: the spine is in N − 1 borders (consecutive pages), not N(N − 1)/2, which
// at 10,000 pages made 50 million border edges and a 14 GB JSON.
TEST(ClusterBorders, ABookWithAClusterPerPageHasLinearlyManyBorders) {
  constexpr std::uint32_t kPages = 5000;
  const Mesh pages = testing::book(kPages);
  std::vector<std::uint32_t> labels(kPages), page(kPages);
  for (std::uint32_t i = 0; i < kPages; ++i) {
    labels[i] = (i * 7919) % kPages;  // shuffled (7919 is prime)
    page[labels[i]] = i;
  }
  const auto borders = cluster_borders(pages, labels);
  ASSERT_EQ(borders.size(), 2 * kPages - 1);
  std::size_t edges = 0;
  for (const ClusterBorder& border : borders) edges += border.edge_count;
  EXPECT_EQ(edges, 3 * kPages - 1);
  for (const ClusterBorder& border : borders) {
    if (border.second == kMeshBoundary) continue;
    // Pages i and i + 1 (by triangle) meet along the spine, one straight curve.
    EXPECT_EQ(std::max(page[border.first], page[border.second]) -
                  std::min(page[border.first], page[border.second]),
              1u);
    ASSERT_EQ(border.curves.size(), 1u);
    EXPECT_EQ(border.curves[0].vertices, (std::vector<std::uint32_t>{0, 1}));
  }
}

TEST(ClusterBorders, RefusesLabelsThatDoNotFit) {
  const GroundTruthShape box = cad_shape("box");
  std::vector<std::uint32_t> labels = box.region_of_face;
  labels.pop_back();
  EXPECT_THROW(cluster_borders(box.mesh, labels), InvalidInputError);
  labels = box.region_of_face;
  labels[3] = 6;
  EXPECT_THROW(cluster_borders(box.mesh, labels, box.regions), InvalidInputError);
  EXPECT_NO_THROW(cluster_borders(box.mesh, labels));  // without primitives, any label
  labels[3] = kMeshBoundary;
  EXPECT_THROW(cluster_borders(box.mesh, labels), InvalidInputError);
}

// On a real part: the curves cover the brute-force borders, the angles are in range, and fandisk's
// sharp edges and fillets both show.
TEST(ClusterBorders, FandiskAtThirtyClusters) {
  const Mesh mesh = read_mesh(testing::cgal_mesh("fandisk.off"));
  const Hierarchy hierarchy = build_hierarchy(mesh);
  const Segmentation level = cut_by_count(hierarchy, 30);
  const std::vector<Primitive> primitives = cluster_primitives(describe_clusters(hierarchy, level));
  const auto borders = cluster_borders(mesh, level.labels, primitives);
  expect_curves_cover_the_borders(mesh, level.labels, borders);
  int sharp = 0, tangent = 0;
  for (const ClusterBorder& border : borders) {
    ASSERT_NE(border.second, kMeshBoundary);  // fandisk is closed
    ASSERT_GE(border.angle, 0);
    ASSERT_LE(border.angle, 180);
    sharp += border.angle > 60;
    tangent += border.angle < 5;
  }
  EXPECT_GE(sharp, 5);
  EXPECT_GE(tangent, 5);
  EXPECT_EQ(cluster_borders(mesh, level.labels, primitives).size(), borders.size());
}

}  // namespace
}  // namespace primseg
