#include "primseg/mesh_distance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "primseg/error.hpp"
#include "primseg/shape_generator.hpp"
#include "shape_generator/random.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using testing::distance;

// A rectangle [0, width] x [0, 1] in the plane z = height, as two triangles.
Mesh rectangle(double width, double height) {
  return Mesh::from_triangles(
      {{0, 0, height}, {width, 0, height}, {width, 1, height}, {0, 1, height}},
      {{0, 1, 2}, {0, 2, 3}});
}

TEST(ClosestPointOnTriangle, MatchesADenseSearchOverTheTriangle) {
  shape_detail::SplitMix64 random(7);
  auto point = [&] {
    return Vec3{random.uniform() * 4 - 2, random.uniform() * 4 - 2, random.uniform() * 4 - 2};
  };
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 a = point(), b = point(), x = point();
    // Every fifth triangle is degenerate: its third corner on the line through a and b.
    const double s = random.uniform() * 3 - 1;
    const Vec3 c = trial % 5 == 0 ? Vec3{a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]),
                                         a[2] + s * (b[2] - a[2])}
                                  : point();
    const Vec3 p = closest_point_on_triangle(x, a, b, c);
    double dense = std::numeric_limits<double>::infinity();
    constexpr int kSteps = 400;
    for (int i = 0; i <= kSteps; ++i)
      for (int j = 0; i + j <= kSteps; ++j) {
        const double u = double(i) / kSteps, v = double(j) / kSteps, w = 1 - u - v;
        const Vec3 q{u * a[0] + v * b[0] + w * c[0], u * a[1] + v * b[1] + w * c[1],
                     u * a[2] + v * b[2] + w * c[2]};
        dense = std::min(dense, distance(x, q));
      }
    const double found = distance(x, p);
    // Never farther than the dense search, and not closer than it by more than its resolution.
    EXPECT_LE(found, dense + 1e-12) << "trial " << trial;
    EXPECT_GE(found, dense - 0.02) << "trial " << trial;
  }
}

TEST(TriangleBvh, AgreesWithBruteForceExactly) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = 0.05;
  options.noise = 0.01;
  const Mesh mesh = make_shape("box_with_hole", options).mesh;
  const TriangleBvh bvh(mesh);
  shape_detail::SplitMix64 random(11);
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3 x{random.uniform() * 3 - 1.5, random.uniform() * 3 - 1.5,
                 random.uniform() * 3 - 1.5};
    double best = std::numeric_limits<double>::infinity();
    std::uint32_t best_triangle = 0;
    for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
      const Triangle& tri = mesh.triangles[t];
      const Vec3 p = closest_point_on_triangle(x, mesh.positions[tri[0]], mesh.positions[tri[1]],
                                               mesh.positions[tri[2]]);
      const double d2 = (p[0] - x[0]) * (p[0] - x[0]) + (p[1] - x[1]) * (p[1] - x[1]) +
                        (p[2] - x[2]) * (p[2] - x[2]);
      if (d2 < best) {
        best = d2;
        best_triangle = t;
      }
    }
    const TriangleBvh::Hit hit = bvh.closest_point(x);
    ASSERT_EQ(hit.squared_distance, best) << "trial " << trial;
    ASSERT_EQ(hit.triangle, best_triangle) << "trial " << trial;
  }
}

TEST(MeshDistance, ParallelRectanglesAreTheirOffsetApart) {
  const MeshDistance d = mesh_distance(rectangle(1, 0), rectangle(1, 0.25));
  EXPECT_NEAR(d.a_to_b.mean, 0.25, 1e-12);
  EXPECT_NEAR(d.a_to_b.rms, 0.25, 1e-12);
  EXPECT_NEAR(d.b_to_a.max, 0.25, 1e-12);
  EXPECT_NEAR(d.hausdorff, 0.25, 1e-12);
  EXPECT_NEAR(d.diagonal, std::sqrt(2 + 0.0625), 1e-12);
}

TEST(MeshDistance, OneSidedFiguresOfAnOverhangMatchTheirIntegrals) {
  // B = [0, 2] x [0, 1] over A = [0, 1] x [0, 1] in one plane: from B, the half x > 1 is at
  // distance x - 1, so mean 1/4, RMS sqrt(1/6), Hausdorff 1 (reached at B's corners); A is on B.
  const MeshDistance d = mesh_distance(rectangle(1, 0), rectangle(2, 0));
  EXPECT_LE(d.a_to_b.max, 1e-12);
  EXPECT_NEAR(d.b_to_a.mean, 0.25, 0.005);
  EXPECT_NEAR(d.b_to_a.rms, std::sqrt(1.0 / 6), 0.005);
  EXPECT_EQ(d.b_to_a.max, 1);
  EXPECT_EQ(d.hausdorff, 1);
  // Symmetric figures are the larger side's (Metro's convention), in either order.
  EXPECT_EQ(d.mean, d.b_to_a.mean);
  EXPECT_EQ(d.rms, d.b_to_a.rms);
  const MeshDistance swapped = mesh_distance(rectangle(2, 0), rectangle(1, 0));
  EXPECT_EQ(swapped.mean, swapped.a_to_b.mean);
  EXPECT_EQ(swapped.rms, swapped.a_to_b.rms);
  EXPECT_EQ(swapped.hausdorff, 1);
  EXPECT_NEAR(d.diagonal, std::sqrt(5.0), 1e-12);  // of both meshes' bounding box
}

TEST(MeshDistance, SameBitsForAnyThreadCountAndDensityCountsSamples) {
  const Mesh sphere = make_shape("sphere").mesh;
  ShapeOptions noisy;
  noisy.noise = 0.01;
  const Mesh other = make_shape("sphere", noisy).mesh;
  DistanceOptions one, two;
  one.threads = 1;
  two.threads = 2;
  one.samples = two.samples = 150000;  // more than one chunk
  const MeshDistance a = mesh_distance(sphere, other, one), b = mesh_distance(sphere, other, two);
  EXPECT_EQ(a.a_to_b.mean, b.a_to_b.mean);
  EXPECT_EQ(a.b_to_a.rms, b.b_to_a.rms);
  EXPECT_EQ(a.hausdorff, b.hausdorff);
  EXPECT_GT(a.rms, 0);

  DistanceOptions dense;
  dense.density = 1000;
  EXPECT_EQ(one_sided_distance(rectangle(2, 0), rectangle(1, 0), dense).samples, 2000u);
}

TEST(MeshDistance, RejectsEmptyMeshesAndBadOptions) {
  const Mesh empty;
  const Mesh flat = Mesh::from_triangles({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {{0, 1, 2}});
  EXPECT_THROW(mesh_distance(empty, rectangle(1, 0)), InvalidInputError);
  EXPECT_THROW(mesh_distance(flat, rectangle(1, 0)), InvalidInputError);
  DistanceOptions options;
  options.samples = 0;
  EXPECT_THROW(mesh_distance(rectangle(1, 0), rectangle(1, 0), options), InvalidInputError);
  // As many samples as a density may ask for, and no more (before, days of queries).
  options.samples = kMaxDistanceSamples + 1;
  EXPECT_THROW(mesh_distance(rectangle(1, 0), rectangle(1, 0), options), InvalidInputError);
  options.samples = 10;
  options.density = -1;
  EXPECT_THROW(mesh_distance(rectangle(1, 0), rectangle(1, 0), options), InvalidInputError);
  options.density = 1e12;
  EXPECT_THROW(mesh_distance(rectangle(1, 0), rectangle(1, 0), options), InvalidInputError);
}

}  // namespace
}  // namespace primseg
