// Bilateral normal smoothing: noise goes, sharp edges stay.

#include "primseg/bilateral_smoothing.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include "primseg/error.hpp"
#include "primseg/mesh_distance.hpp"
#include "primseg/shape_generator.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

GroundTruthShape uniform_box(double noise) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = 0.04;
  options.noise = noise;
  return make_shape("box", options);
}

// Largest distance of a vertex from the nearest of the box's six face planes: zero for a vertex
// on the box, whatever face or edge it lies on.
double largest_distance_to_box(const Mesh& mesh, const std::vector<Primitive>& planes) {
  double largest = 0;
  for (const Vec3& x : mesh.positions) {
    double nearest = INFINITY;
    for (const Primitive& plane : planes) nearest = std::min(nearest, plane.distance(x));
    largest = std::max(largest, nearest);
  }
  return largest;
}

TEST(BilateralSmoothing, NoiseOnABoxDropsAndItsEdgesStaySharp) {
  const GroundTruthShape clean = uniform_box(0);
  const GroundTruthShape noisy = uniform_box(0.004);
  const Mesh smoothed = bilateral_smooth(noisy.mesh);
  ASSERT_EQ(smoothed.triangles, noisy.mesh.triangles);
  DistanceOptions measure;
  measure.samples = 50000;
  const double before = mesh_distance(noisy.mesh, clean.mesh, measure).rms;
  const double after = mesh_distance(smoothed, clean.mesh, measure).rms;
  EXPECT_LT(after * 3, before) << "before " << before << ", after " << after;

  // Uniform smoothing rounds the edges: vertices on them are pulled inside by about an edge
  // length after a few steps. Bilateral filtering keeps every vertex near a face plane.
  const double diagonal = bounding_box_diagonal(clean.mesh);
  EXPECT_LT(largest_distance_to_box(smoothed, clean.regions), 0.02 * diagonal);
}

TEST(BilateralSmoothing, LeavesAnExactBoxNearlyWhereItIs) {
  const GroundTruthShape box = uniform_box(0);
  const Mesh smoothed = bilateral_smooth(box.mesh);
  // Across a 90-degree edge normals differ by sqrt(2): weight exp(-2 / (2 * 0.35^2)) = 3e-4.
  EXPECT_LT(largest_distance_to_box(smoothed, box.regions), 1e-3 * bounding_box_diagonal(box.mesh));
}

TEST(BilateralSmoothing, IsDeterministicAndKeepsConnectivity) {
  const Mesh noisy = uniform_box(0.004).mesh;
  const Mesh a = bilateral_smooth(noisy), b = bilateral_smooth(noisy);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.face_of_triangle, noisy.face_of_triangle);
  // The same, bit for bit, on any number of threads (the box has enough faces for three).
  ASSERT_GE(noisy.triangle_count(), 2 * 1024u);
  for (const unsigned threads : {1u, 2u, 3u}) {
    BilateralSmoothingOptions options;
    options.threads = threads;
    EXPECT_EQ(bilateral_smooth(noisy, options).positions, a.positions) << threads << " threads";
  }
}

// Files from scanners and CAD exports often list faces with inconsistent orientations. Normals are
// compared once the faces are consistently oriented: otherwise a flipped neighbour of a flat face
// would not average with it, and one across a sharp wedge would look nearly parallel.
TEST(BilateralSmoothing, DoesNotDependOnTheFacesOrientations) {
  const Mesh noisy = uniform_box(0.004).mesh;
  ASSERT_EQ(noisy.face_count(), noisy.triangle_count());
  std::vector<Triangle> triangles = noisy.triangles;
  for (std::size_t t = 0; t < triangles.size(); t += 2)
    std::swap(triangles[t][1], triangles[t][2]);  // the same first corner
  const Mesh shuffled = Mesh::from_triangles(noisy.positions, triangles);
  const Mesh smoothed = bilateral_smooth(shuffled);
  EXPECT_EQ(smoothed.triangles, shuffled.triangles);
  // The same up to round-off (a triangle's centroid sums its corners in another order).
  const Mesh reference = bilateral_smooth(noisy);
  for (std::size_t v = 0; v < noisy.positions.size(); ++v)
    for (int k = 0; k < 3; ++k)
      ASSERT_NEAR(smoothed.positions[v][k], reference.positions[v][k], 1e-12) << v;

  // A tetrahedron (unit edges along the axes) with two of its faces listed inwards. No noise, so
  // little moves: across its right-angled edges normals average a little (weight 3e-4, see
  // above). Compared as listed, its corners moved by 0.14 to 0.34.
  const testing::TetrahedronWithInwardFaces tetrahedron;
  const Mesh still = bilateral_smooth(tetrahedron.mesh);
  for (std::size_t v = 0; v < tetrahedron.corners.size(); ++v)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(still.positions[v][k], tetrahedron.corners[v][k], 5e-3) << v;
}

// A book's spine is on every page: with all the faces around a vertex in a face's ring, each of
// 20,000 rings would hold every page (400 million entries, 1.6 GB, read 20 times). Above 64
// triangles a vertex brings only the faces across its edges; the spine and the pages stay.
TEST(BilateralSmoothing, ABookOfManyPagesKeepsItsPagesWhereTheyAre) {
  const Mesh pages = testing::book(20000);
  const Mesh smoothed = bilateral_smooth(pages);
  ASSERT_LT(testing::distance(smoothed.positions[0], pages.positions[0]), 1e-9);
  ASSERT_LT(testing::distance(smoothed.positions[1], pages.positions[1]), 1e-9);
  // Consecutive pages are 3e-4 rad apart, a smooth fold to the filter; only where the spine's
  // chain ends (pages 0 and N − 1) do the normals average one-sided, moving a few corners by
  // under 0.04% of the diagonal.
  for (std::uint32_t v = 2; v < pages.vertex_count(); ++v)
    ASSERT_LT(testing::distance(smoothed.positions[v], pages.positions[v]), 1e-3) << v;
}

// A fan of many slivers round one hub vertex, noisy along z: the faces across each edge are still
// neighbours enough to smooth it (RMS height 2.2x lower; the vertex rings, every sliver through
// the hub, would take 20,000² steps a pass).
TEST(BilateralSmoothing, ANoisyFanRoundAHubOfManyTrianglesIsSmoothed) {
  constexpr std::uint32_t kSlivers = 20000;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0, 2e-6);
  std::vector<Vec3> positions = {{0, 0, 0}};
  std::vector<Triangle> triangles;
  for (std::uint32_t i = 0; i < kSlivers; ++i) {
    const double angle = 2 * std::numbers::pi * i / kSlivers;
    positions.push_back({std::cos(angle), std::sin(angle), noise(rng)});
    triangles.push_back({0, i + 1, (i + 1) % kSlivers + 1});
  }
  const Mesh fan = Mesh::from_triangles(positions, triangles);
  const auto rms_height = [](const Mesh& mesh) {
    double sum = 0;
    for (const Vec3& x : mesh.positions) sum += x[2] * x[2];
    return std::sqrt(sum / static_cast<double>(mesh.vertex_count()));
  };
  const double before = rms_height(fan), after = rms_height(bilateral_smooth(fan));
  EXPECT_LT(after * 1.6, before) << "before " << before << ", after " << after;
}

TEST(BilateralSmoothing, ZeroIterationsChangeNothing) {
  const Mesh noisy = uniform_box(0.004).mesh;
  BilateralSmoothingOptions options;
  options.normal_iterations = 0;
  options.vertex_iterations = 0;
  EXPECT_EQ(bilateral_smooth(noisy, options).positions, noisy.positions);
}

TEST(BilateralSmoothing, RejectsBadOptions) {
  const Mesh box = uniform_box(0).mesh;
  BilateralSmoothingOptions options;
  options.normal_sigma = 0;
  EXPECT_THROW(bilateral_smooth(box, options), InvalidInputError);
  options = {};
  options.spatial_sigma = NAN;
  EXPECT_THROW(bilateral_smooth(box, options), InvalidInputError);
  options = {};
  options.vertex_iterations = -1;
  EXPECT_THROW(bilateral_smooth(box, options), InvalidInputError);
}

}  // namespace
}  // namespace primseg
