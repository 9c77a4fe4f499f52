#include "primseg/shape_generator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <numbers>
#include <numeric>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "primseg/error.hpp"

namespace primseg {
namespace {

constexpr double kPi = std::numbers::pi;

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}

double diagonal(const Mesh& mesh) {
  Vec3 lo = mesh.positions[0], hi = mesh.positions[0];
  for (const Vec3& p : mesh.positions) {
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  }
  return norm(sub(hi, lo));
}

/// Distance to the analytic surface; independent of Primitive::distance on purpose.
double distance_to(const Primitive& primitive, const Vec3& x) {
  const Vec3 d = sub(x, primitive.point);
  switch (primitive.type) {
    case PrimitiveType::Plane:
      return std::abs(dot(d, primitive.axis));
    case PrimitiveType::Cylinder: {
      const double along = dot(d, primitive.axis);
      return std::abs(std::sqrt(std::max(0.0, dot(d, d) - along * along)) - primitive.radius);
    }
    case PrimitiveType::Sphere:
      return std::abs(norm(d) - primitive.radius);
    case PrimitiveType::Cone: {
      // In the (along, across) half-plane: distance to the generator ray from the apex.
      const double along = dot(d, primitive.axis);
      const double across = std::sqrt(std::max(0.0, dot(d, d) - along * along));
      const double c = std::cos(primitive.half_angle), s = std::sin(primitive.half_angle);
      if (along * c + across * s < 0) return norm(d);
      return std::abs(across * c - along * s);
    }
    case PrimitiveType::Torus: {
      const double along = dot(d, primitive.axis);
      const double across = std::sqrt(std::max(0.0, dot(d, d) - along * along));
      return std::abs(std::hypot(across - primitive.radius, along) - primitive.minor_radius);
    }
    default:
      ADD_FAILURE() << "unexpected primitive type";
      return 0;
  }
}

double signed_volume(const Mesh& mesh) {
  double six_volume = 0;
  for (const Triangle& t : mesh.triangles) {
    six_volume += dot(mesh.positions[t[0]], cross(mesh.positions[t[1]], mesh.positions[t[2]]));
  }
  return six_volume / 6;
}

std::pair<std::uint32_t, std::uint32_t> undirected(std::uint32_t a, std::uint32_t b) {
  return std::minmax(a, b);
}

/// Number of connected components of the faces accepted by `keep`, joined across shared edges.
template <typename Keep>
int edge_components(const Mesh& mesh, Keep keep) {
  std::vector<std::uint32_t> parent(mesh.triangles.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t f) {
    while (parent[f] != f) f = parent[f] = parent[parent[f]];
    return f;
  };
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> first_face_of_edge;
  int components = 0;
  for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f) {
    if (!keep(f)) continue;
    ++components;
    const Triangle& t = mesh.triangles[f];
    for (int i = 0; i < 3; ++i) {
      auto [it, inserted] = first_face_of_edge.try_emplace(undirected(t[i], t[(i + 1) % 3]), f);
      if (inserted) continue;
      const std::uint32_t a = find(it->second), b = find(f);
      if (a != b) parent[a] = b, --components;
    }
  }
  return components;
}

struct Expectation {
  std::size_t regions;
  double volume;
};

const std::map<std::string, Expectation>& expectations() {
  const double box = 1.6 * 1.2 * 0.8;
  const double dome_height = 0.6 - std::sqrt(0.36 - 0.45 * 0.45);
  static const std::map<std::string, Expectation> table{
      {"box", {6, box}},
      {"slanted_box", {7, box - 0.6 * 0.45 * 0.35 / 6}},
      {"capped_cylinder", {3, kPi * 0.25 * 1.2}},
      {"sphere", {1, 4.0 / 3 * kPi * 0.512}},
      {"box_with_hole", {7, box - kPi * 0.09 * 0.8}},
      {"box_with_blind_hole", {8, box - kPi * 0.09 * 0.5}},
      {"box_with_boss", {8, 1.6 * 1.2 * 0.6 + kPi * 0.35 * 0.35 * 0.4}},
      {"box_with_dome",
       {7, 1.6 * 1.2 * 0.6 + kPi * dome_height * dome_height * (3 * 0.6 - dome_height) / 3}},
      {"stepped_block", {8, 1.2}},
      {"cylinder_with_sphere_cap", {3, kPi * 0.25 + 2.0 / 3 * kPi * 0.125}},
      // Cylinder to the chamfer, then a frustum of height 0.1 from radius 0.5 to 0.4.
      {"chamfered_cylinder", {4, kPi * 0.25 * 1.1 + kPi * 0.1 / 3 * (0.25 + 0.2 + 0.16)}},
      // Cylinder to the fillet, then a disc of radius 0.35 and the quarter disc of radius 0.15
      // around the tube's centre circle (Pappus).
      {"filleted_cylinder",
       {4, kPi * 0.25 * 1.05 + kPi * 0.35 * 0.35 * 0.15 +
               2 * kPi * (0.35 + 4 * 0.15 / (3 * kPi)) * kPi * 0.15 * 0.15 / 4}},
      // Through-hole of radius 0.2 below a frustum of height 0.15 from radius 0.2 to 0.35.
      {"box_with_countersink",
       {8, box - kPi * 0.04 * 0.65 - kPi * 0.15 / 3 * (0.04 + 0.07 + 0.1225)}},
  };
  return table;
}

TEST(ShapeGenerator, CatalogueIsFixed) {
  const std::vector<std::string> expected{"box",
                                          "slanted_box",
                                          "capped_cylinder",
                                          "sphere",
                                          "box_with_hole",
                                          "box_with_blind_hole",
                                          "box_with_boss",
                                          "box_with_dome",
                                          "stepped_block",
                                          "cylinder_with_sphere_cap",
                                          "chamfered_cylinder",
                                          "filleted_cylinder",
                                          "box_with_countersink"};
  EXPECT_EQ(shape_names(), expected);
}

TEST(ShapeGenerator, UnknownNameThrows) {
  EXPECT_THROW(make_shape("dodecahedron"), InvalidInputError);
  EXPECT_THROW(make_shape(""), InvalidInputError);
}

TEST(ShapeGenerator, OptionsOutOfRangeThrow) {
  ShapeOptions options;
  options.edge_length = 0;
  EXPECT_THROW(make_shape("box", options), InvalidInputError);
  options = {};
  options.segments = 2;
  EXPECT_THROW(make_shape("box", options), InvalidInputError);
  options = {};
  options.noise = -0.1;
  EXPECT_THROW(make_shape("box", options), InvalidInputError);
}

TEST(ShapeGenerator, CadBoxHasTwelveTriangles) {
  const GroundTruthShape shape = make_shape("box");
  EXPECT_EQ(shape.mesh.face_count(), 12u);
  EXPECT_EQ(shape.mesh.vertex_count(), 8u);
}

TEST(ShapeGenerator, CadCylinderIsOneStripAndTwoFans) {
  ShapeOptions options;
  options.segments = 32;
  const GroundTruthShape shape = make_shape("capped_cylinder", options);
  // 2 x 32 strip triangles, and 32 - 2 per disc: no vertex inside any face.
  EXPECT_EQ(shape.mesh.face_count(), 64u + 30u + 30u);
  EXPECT_EQ(shape.mesh.vertex_count(), 64u);
}

TEST(ShapeGenerator, CadPlanarFacesHaveNoInteriorVertices) {
  // A triangulation of a polygon with V boundary vertices and H holes and no interior vertex
  // has V + 2H - 2 triangles; the top face of box_with_hole has V = 4 + 48, H = 1.
  const GroundTruthShape shape = make_shape("box_with_hole");
  std::vector<int> faces_of_region(shape.regions.size(), 0);
  for (std::uint32_t r : shape.region_of_face) ++faces_of_region[r];
  const std::uint32_t top = 5;  // regions: -x, +x, -y, +y, -z, +z, hole
  EXPECT_EQ(faces_of_region[top], 4 + 48 + 2 - 2);
  EXPECT_EQ(faces_of_region[0], 2);
}

using ShapeCase = std::tuple<std::string, Tessellation>;

class EveryShape : public ::testing::TestWithParam<ShapeCase> {
 protected:
  ShapeOptions options() const {
    ShapeOptions o;
    o.tessellation = std::get<1>(GetParam());
    return o;
  }
  const std::string& name() const { return std::get<0>(GetParam()); }
};

TEST_P(EveryShape, IsClosedManifoldAndOutwardOriented) {
  const GroundTruthShape shape = make_shape(name(), options());
  const Mesh& mesh = shape.mesh;
  ASSERT_GT(mesh.face_count(), 0u);
  EXPECT_EQ(shape.name, name());
  EXPECT_EQ(mesh.triangle_count(), mesh.face_count());
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const Triangle& t : mesh.triangles) {
    ASSERT_TRUE(t[0] != t[1] && t[1] != t[2] && t[2] != t[0]);
    for (int i = 0; i < 3; ++i) ++directed[{t[i], t[(i + 1) % 3]}];
  }
  for (const auto& [edge, count] : directed) {
    // Each undirected edge has exactly two faces that traverse it in opposite directions.
    ASSERT_EQ(count, 1) << "edge " << edge.first << "-" << edge.second << " repeated";
    ASSERT_EQ(directed.count({edge.second, edge.first}), 1u)
        << "boundary edge " << edge.first << "-" << edge.second;
  }
  std::vector<bool> used(mesh.positions.size(), false);
  for (const Triangle& t : mesh.triangles) used[t[0]] = used[t[1]] = used[t[2]] = true;
  EXPECT_EQ(std::count(used.begin(), used.end(), false), 0) << "isolated vertices";
  EXPECT_EQ(edge_components(mesh, [](std::uint32_t) { return true; }), 1);
  // Euler characteristic of a sphere (every catalogue shape has genus 0 except the through hole).
  const auto v = static_cast<long>(mesh.vertex_count()), f = static_cast<long>(mesh.face_count());
  const long e = static_cast<long>(directed.size()) / 2;
  EXPECT_EQ(v - e + f, (name() == "box_with_hole" || name() == "box_with_countersink") ? 0 : 2);
  EXPECT_GT(signed_volume(mesh), 0);
}

TEST_P(EveryShape, SatisfiesTheMeshInvariants) {
  const GroundTruthShape shape = make_shape(name(), options());
  EXPECT_NO_THROW(shape.mesh.validate());
  EXPECT_NEAR(bounding_box_diagonal(shape.mesh), diagonal(shape.mesh), 1e-12);
}

TEST_P(EveryShape, VolumeMatchesTheSolid) {
  const GroundTruthShape shape = make_shape(name(), options());
  const double expected = expectations().at(name()).volume;
  EXPECT_NEAR(signed_volume(shape.mesh), expected, 0.02 * expected);
}

TEST_P(EveryShape, RegionsAreLabelledAndEdgeConnected) {
  const GroundTruthShape shape = make_shape(name(), options());
  const std::size_t region_count = expectations().at(name()).regions;
  ASSERT_EQ(shape.regions.size(), region_count);
  ASSERT_EQ(shape.region_of_face.size(), shape.mesh.face_count());
  for (std::uint32_t r = 0; r < region_count; ++r) {
    EXPECT_EQ(
        edge_components(shape.mesh, [&](std::uint32_t f) { return shape.region_of_face[f] == r; }),
        1)
        << "region " << r;
  }
}

void expect_vertices_on_primitives(const GroundTruthShape& shape) {
  const double tolerance = 1e-9 * diagonal(shape.mesh);
  double worst = 0;
  for (std::uint32_t f = 0; f < shape.mesh.face_count(); ++f) {
    const Primitive& primitive = shape.regions[shape.region_of_face[f]];
    for (std::uint32_t v : shape.mesh.triangles[f]) {
      worst = std::max(worst, distance_to(primitive, shape.mesh.positions[v]));
    }
  }
  EXPECT_LE(worst, tolerance) << shape.name;
}

/// The canonical form of primitive.hpp, and outward plane normals.
void expect_canonical_primitives(const GroundTruthShape& shape) {
  const Mesh& mesh = shape.mesh;
  for (std::uint32_t r = 0; r < shape.regions.size(); ++r) {
    const Primitive& primitive = shape.regions[r];
    Vec3 area_normal{0, 0, 0}, weighted_centroid{0, 0, 0};
    double area = 0;
    for (std::uint32_t f = 0; f < mesh.face_count(); ++f) {
      if (shape.region_of_face[f] != r) continue;
      const Vec3 &a = mesh.positions[mesh.triangles[f][0]],
                 &b = mesh.positions[mesh.triangles[f][1]],
                 &c = mesh.positions[mesh.triangles[f][2]];
      const Vec3 n = cross(sub(b, a), sub(c, a));
      for (int k = 0; k < 3; ++k) {
        area_normal[k] += n[k];
        weighted_centroid[k] += norm(n) * (a[k] + b[k] + c[k]) / 6;
      }
      area += norm(n) / 2;
    }
    const Vec3 centroid{weighted_centroid[0] / area, weighted_centroid[1] / area,
                        weighted_centroid[2] / area};
    const double diag = diagonal(mesh);
    switch (primitive.type) {
      case PrimitiveType::Plane:
        EXPECT_NEAR(norm(primitive.axis), 1, 1e-12);
        EXPECT_NEAR(dot(area_normal, primitive.axis), norm(area_normal), 1e-9 * norm(area_normal));
        EXPECT_LE(norm(sub(centroid, primitive.point)), 1e-9 * diag);
        break;
      case PrimitiveType::Cylinder: {
        EXPECT_NEAR(norm(primitive.axis), 1, 1e-12);
        const auto largest =
            *std::max_element(primitive.axis.begin(), primitive.axis.end(),
                              [](double u, double v) { return std::abs(u) < std::abs(v); });
        EXPECT_GT(largest, 0);
        EXPECT_LE(std::abs(dot(sub(centroid, primitive.point), primitive.axis)), 1e-9 * diag);
        EXPECT_GT(primitive.radius, 0);
        break;
      }
      case PrimitiveType::Sphere:
        EXPECT_GT(primitive.radius, 0);
        break;
      case PrimitiveType::Cone:
        EXPECT_NEAR(norm(primitive.axis), 1, 1e-12);
        // The region lies on the side of the apex the axis points to.
        EXPECT_GT(dot(sub(centroid, primitive.point), primitive.axis), 0);
        EXPECT_GT(primitive.half_angle, 0);
        EXPECT_LT(primitive.half_angle, kPi / 2);
        break;
      case PrimitiveType::Torus: {
        EXPECT_NEAR(norm(primitive.axis), 1, 1e-12);
        const auto largest =
            *std::max_element(primitive.axis.begin(), primitive.axis.end(),
                              [](double u, double v) { return std::abs(u) < std::abs(v); });
        EXPECT_GT(largest, 0);
        EXPECT_GT(primitive.minor_radius, 0);
        EXPECT_GT(primitive.radius, primitive.minor_radius);
        break;
      }
      default:
        ADD_FAILURE() << "unexpected primitive";
    }
  }
}

TEST_P(EveryShape, VerticesLieOnTheirRegionPrimitive) {
  const GroundTruthShape shape = make_shape(name(), options());
  expect_vertices_on_primitives(shape);
  expect_canonical_primitives(shape);
}

TEST_P(EveryShape, VerticesLieOnTheirRegionPrimitiveAfterRandomMotion) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    ShapeOptions moved = options();
    moved.random_motion = true;
    moved.seed = seed;
    const GroundTruthShape shape = make_shape(name(), moved);
    expect_vertices_on_primitives(shape);
    expect_canonical_primitives(shape);
    EXPECT_GT(signed_volume(shape.mesh), 0);
  }
}

TEST_P(EveryShape, IsDeterministic) {
  ShapeOptions o = options();
  o.random_motion = true;
  o.noise = 0.01;
  o.seed = 42;
  const GroundTruthShape first = make_shape(name(), o);
  const GroundTruthShape second = make_shape(name(), o);
  ASSERT_EQ(first.mesh.positions.size(), second.mesh.positions.size());
  EXPECT_EQ(std::memcmp(first.mesh.positions.data(), second.mesh.positions.data(),
                        first.mesh.positions.size() * sizeof(Vec3)),
            0);
  EXPECT_EQ(first.mesh.triangles, second.mesh.triangles);
  EXPECT_EQ(first.region_of_face, second.region_of_face);
  o.seed = 43;
  const GroundTruthShape other = make_shape(name(), o);
  EXPECT_NE(std::memcmp(first.mesh.positions.data(), other.mesh.positions.data(),
                        first.mesh.positions.size() * sizeof(Vec3)),
            0);
}

INSTANTIATE_TEST_SUITE_P(Catalogue, EveryShape,
                         ::testing::Combine(::testing::ValuesIn(shape_names()),
                                            ::testing::Values(Tessellation::Cad,
                                                              Tessellation::Uniform)),
                         [](const ::testing::TestParamInfo<ShapeCase>& param_info) {
                           return std::get<0>(param_info.param) +
                                  (std::get<1>(param_info.param) == Tessellation::Cad ? "_Cad"
                                                                                      : "_Uniform");
                         });

struct EdgeStatistics {
  double longest = 0, shortest = INFINITY, smallest_angle_degrees = 180;
};

EdgeStatistics edge_statistics(const Mesh& mesh) {
  EdgeStatistics stats;
  for (const Triangle& t : mesh.triangles) {
    for (int i = 0; i < 3; ++i) {
      const Vec3 &a = mesh.positions[t[i]], &b = mesh.positions[t[(i + 1) % 3]],
                 &c = mesh.positions[t[(i + 2) % 3]];
      const double length = norm(sub(b, a));
      stats.longest = std::max(stats.longest, length);
      stats.shortest = std::min(stats.shortest, length);
      const Vec3 u = sub(b, a), w = sub(c, a);
      const double angle = std::atan2(norm(cross(u, w)), dot(u, w)) * 180 / kPi;
      stats.smallest_angle_degrees = std::min(stats.smallest_angle_degrees, angle);
    }
  }
  return stats;
}

class UniformQuality : public ::testing::TestWithParam<std::tuple<std::string, double>> {};

TEST_P(UniformQuality, EdgesNearTargetAndNoSlivers) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = std::get<1>(GetParam());
  const GroundTruthShape shape = make_shape(std::get<0>(GetParam()), options);
  const double target = options.edge_length * diagonal(shape.mesh);
  const EdgeStatistics stats = edge_statistics(shape.mesh);
  EXPECT_LE(stats.longest, 1.75 * target);
  EXPECT_GE(stats.shortest, 0.25 * target);
  EXPECT_GE(stats.smallest_angle_degrees, 20.0);
}

INSTANTIATE_TEST_SUITE_P(Catalogue, UniformQuality,
                         ::testing::Combine(::testing::ValuesIn(shape_names()),
                                            ::testing::Values(0.05, 0.02)),
                         [](const auto& param_info) {
                           return std::get<0>(param_info.param) + "_" +
                                  std::to_string(
                                      static_cast<int>(std::get<1>(param_info.param) * 1000));
                         });

TEST(ShapeGenerator, UniformSphereIsFineAndAccurate) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = 0.02;
  const GroundTruthShape shape = make_shape("sphere", options);
  const double expected = 4.0 / 3 * kPi * 0.512;
  EXPECT_NEAR(signed_volume(shape.mesh), expected, 0.01 * expected);
}

TEST(ShapeGenerator, NoiseMovesVerticesAlongNormalsByTheRequestedAmount) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = 0.02;
  options.random_motion = true;
  const GroundTruthShape exact = make_shape("box_with_dome", options);
  options.noise = 0.01;
  const GroundTruthShape noisy = make_shape("box_with_dome", options);
  ASSERT_EQ(exact.mesh.positions.size(), noisy.mesh.positions.size());
  EXPECT_EQ(exact.mesh.triangles, noisy.mesh.triangles);
  EXPECT_EQ(exact.region_of_face, noisy.region_of_face);
  double sum_squares = 0;
  for (std::size_t v = 0; v < exact.mesh.positions.size(); ++v) {
    const double d = norm(sub(exact.mesh.positions[v], noisy.mesh.positions[v]));
    sum_squares += d * d;
  }
  const double rms = std::sqrt(sum_squares / static_cast<double>(exact.mesh.positions.size()));
  const double expected = 0.01 * diagonal(exact.mesh);
  EXPECT_NEAR(rms, expected, 0.2 * expected);
  // Primitives describe the noise-free surface.
  for (std::size_t r = 0; r < exact.regions.size(); ++r) {
    EXPECT_EQ(exact.regions[r].type, noisy.regions[r].type);
    EXPECT_EQ(exact.regions[r].point, noisy.regions[r].point);
    EXPECT_EQ(exact.regions[r].axis, noisy.regions[r].axis);
    EXPECT_EQ(exact.regions[r].radius, noisy.regions[r].radius);
  }
}

TEST(ShapeGenerator, FineUniformShapesAreQuick) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = 0.01;
  for (const std::string& name : shape_names()) {
    const auto start = std::chrono::steady_clock::now();
    const GroundTruthShape shape = make_shape(name, options);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // Generous: Debug and sanitizer builds are several times slower than Release.
    EXPECT_LT(seconds, 10.0) << name;
    RecordProperty(name + "_faces", static_cast<int>(shape.mesh.face_count()));
  }
}

}  // namespace
}  // namespace primseg

namespace primseg {
namespace {

/// Closed, manifold, outward and on-primitive across the whole option range, not only at the
/// defaults (coarse circles, triangular holes, huge or tiny Uniform edges).
TEST(ShapeGenerator, ValidAcrossOptionRanges) {
  std::vector<ShapeOptions> variants;
  for (int segments : {3, 4, 5, 7, 16, 100}) {
    ShapeOptions o;
    o.segments = segments;
    variants.push_back(o);
  }
  for (double edge_length : {1.0, 0.5, 0.3, 0.2, 0.12, 0.07, 0.03}) {
    ShapeOptions o;
    o.tessellation = Tessellation::Uniform;
    o.edge_length = edge_length;
    variants.push_back(o);
  }
  for (const ShapeOptions& options : variants) {
    for (const std::string& name : shape_names()) {
      SCOPED_TRACE(name + " segments " + std::to_string(options.segments) + " edge_length " +
                   std::to_string(options.edge_length));
      const GroundTruthShape shape = make_shape(name, options);
      std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
      for (const Triangle& t : shape.mesh.triangles) {
        for (int i = 0; i < 3; ++i) ++directed[{t[i], t[(i + 1) % 3]}];
      }
      bool manifold = true;
      for (const auto& [edge, count] : directed) {
        manifold = manifold && count == 1 && directed.count({edge.second, edge.first}) == 1;
      }
      EXPECT_TRUE(manifold);
      EXPECT_GT(signed_volume(shape.mesh), 0);
      EXPECT_EQ(edge_components(shape.mesh, [](std::uint32_t) { return true; }), 1);
      for (std::uint32_t r = 0; r < shape.regions.size(); ++r) {
        EXPECT_EQ(edge_components(shape.mesh,
                                  [&](std::uint32_t f) { return shape.region_of_face[f] == r; }),
                  1);
      }
      expect_vertices_on_primitives(shape);
    }
  }
}

}  // namespace
}  // namespace primseg
