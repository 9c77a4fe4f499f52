// Regions (HierarchyOptions::regions): an approximate merge order whose first merges are made in
// regions of the mesh side by side. Its trees must be valid, deterministic, and as good as the
// exact order's where users cut them.
#include "hierarchy_regions.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "face_triangles.hpp"
#include "primseg/cut.hpp"
#include "primseg/dual_graph.hpp"
#include "primseg/error.hpp"
#include "primseg/evaluation.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"
#include "primseg/tree_io.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using detail::kMinRegionFaces;
using detail::kRegionFacesPerCluster;
using testing::level_rms;

// A generated shape of 11,520 to 20,868 uniform triangles (two regions of at least 4,096).
GroundTruthShape large_shape(const std::string& name, double noise, std::uint64_t seed = 1) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = 0.015;
  options.noise = noise;
  options.random_motion = true;
  options.seed = seed;
  return make_shape(name, options);
}

HierarchyOptions in_regions(unsigned regions, unsigned threads = 0) {
  HierarchyOptions options;
  options.regions = regions;
  options.threads = threads;
  return options;
}

std::array<double, 3> first_centroid(const Mesh& mesh, std::uint32_t face) {
  const auto t = static_cast<std::uint32_t>(
      std::lower_bound(mesh.face_of_triangle.begin(), mesh.face_of_triangle.end(), face) -
      mesh.face_of_triangle.begin());
  std::array<double, 3> c{};
  for (const std::uint32_t v : mesh.triangles[t])
    for (int a = 0; a < 3; ++a) c[a] += mesh.positions[v][a] / 3;
  return c;
}

TEST(SplitIntoRegions, GivesEveryFaceOnceInRegionsOfNearlyEqualSize) {
  const Mesh mesh = large_shape("box_with_hole", 0.002).mesh;
  const std::uint32_t f = mesh.face_count();
  for (unsigned count : {1u, 2u, 3u, 4u, 7u}) {
    const auto regions = detail::split_into_regions(mesh, count);
    ASSERT_EQ(regions.size(), count);
    std::vector<int> seen(f, 0);
    for (const auto& region : regions) {
      EXPECT_TRUE(std::is_sorted(region.begin(), region.end()));
      EXPECT_GE(region.size(), f / count - 1) << count;
      EXPECT_LE(region.size(), f / count + 1) << count;
      for (const std::uint32_t face : region) ++seen[face];
    }
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), std::ptrdiff_t(f)) << count;
  }
  // Two regions lie on either side of a plane across the longest side of the box of centroids.
  const auto halves = detail::split_into_regions(mesh, 2);
  double best_gap = -INFINITY;
  for (int axis = 0; axis < 3; ++axis) {
    double high0 = -INFINITY, low1 = INFINITY;
    for (std::uint32_t face : halves[0]) high0 = std::max(high0, first_centroid(mesh, face)[axis]);
    for (std::uint32_t face : halves[1]) low1 = std::min(low1, first_centroid(mesh, face)[axis]);
    best_gap = std::max(best_gap, low1 - high0);
  }
  EXPECT_GE(best_gap, 0.0);
}

TEST(RegionMesh, KeepsThePolygonsTheirTrianglesAndPositions) {
  // Two quads and a triangle; the region takes the second quad and the triangle.
  const Mesh mesh = Mesh::from_polygons(
      {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {2, 1, 0}, {3, 0, 0}}, {0, 4, 8, 11},
      {0, 1, 2, 3, 1, 4, 5, 2, 4, 6, 5});
  const Mesh region = detail::region_mesh(mesh, detail::first_triangles(mesh), {1, 2});
  region.validate();
  ASSERT_EQ(region.face_count(), 2u);
  EXPECT_EQ(region.vertex_count(), 5u);  // only the vertices the faces use
  for (std::uint32_t i = 0; i < 2; ++i) {
    const auto original = mesh.polygon(i + 1), kept = region.polygon(i);
    ASSERT_EQ(original.size(), kept.size());
    for (std::size_t k = 0; k < kept.size(); ++k)
      EXPECT_EQ(region.positions[kept[k]], mesh.positions[original[k]]);
  }
  EXPECT_EQ(region.triangle_count(), 3u);
  EXPECT_EQ(region.face_of_triangle, (std::vector<std::uint32_t>{0, 0, 1}));
}

// The tree passes every check a tree file gets, is the same for any number of threads and when
// built step by step, and its first merges stay inside their regions.
TEST(HierarchyRegions, TreeIsValidDeterministicAndItsFirstMergesStayInTheirRegions) {
  // Two components, so that trailing merges follow the regions' and the whole mesh's merges.
  GroundTruthShape second = large_shape("capped_cylinder", 0.002, 2);
  for (Vec3& p : second.mesh.positions) p[0] += 1000;
  const auto mesh = std::make_shared<const Mesh>(
      testing::concatenated({large_shape("box_with_boss", 0.002).mesh, second.mesh}));
  const std::uint32_t f = mesh->face_count();
  const std::string reference = serialize_tree(build_hierarchy(mesh, in_regions(2, 1)));
  for (unsigned threads : {2u, 3u})
    EXPECT_EQ(serialize_tree(build_hierarchy(mesh, in_regions(2, threads))), reference) << threads;

  HierarchyBuilder builder(mesh, in_regions(2));
  const std::uint32_t prefix = builder.merge_count();
  EXPECT_GT(prefix, f - f / kRegionFacesPerCluster - 4);
  EXPECT_EQ(builder.merges().size(), prefix);
  std::uint32_t steps = prefix;
  while (builder.step()) ASSERT_EQ(builder.merge_count(), ++steps);
  EXPECT_EQ(steps, builder.total_merge_count());
  EXPECT_EQ(steps, f - 2);
  const Hierarchy tree = builder.finish();
  EXPECT_EQ(serialize_tree(tree), reference);
  // What Hierarchy's checked constructor (and so deserialize_tree) accepts.
  EXPECT_NO_THROW(Hierarchy(mesh, in_regions(2),
                            std::vector<Merge>(tree.merges().begin(), tree.merges().end())));

  // At the level the regions stopped at, every cluster is inside one region.
  const auto regions = detail::split_into_regions(*mesh, 2);
  std::vector<int> region_of(f);
  for (int r = 0; r < 2; ++r)
    for (std::uint32_t face : regions[r]) region_of[face] = r;
  const Segmentation level = cut_by_count(tree, f - prefix);
  std::vector<std::set<int>> regions_of_cluster(level.cluster_count());
  for (std::uint32_t face = 0; face < f; ++face)
    regions_of_cluster[level.labels[face]].insert(region_of[face]);
  for (const auto& in : regions_of_cluster) EXPECT_EQ(in.size(), 1u);
}

// A strip of 4 triangles, each linked to the next: merges must join linked clusters.
TEST(HierarchyRegions, MergesMustJoinLinkedClusters) {
  const Mesh strip =
      Mesh::from_triangles({{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {2, 0, 0}, {2, 1, 0}},
                           {{0, 2, 1}, {1, 2, 3}, {2, 4, 3}, {3, 4, 5}});
  const DualGraph graph(strip, VertexWeights::Area, 1);
  ASSERT_EQ(graph.edges().size(), 3u);
  auto merge = [](std::uint32_t a, std::uint32_t b) {
    Merge m;
    m.first = a;
    m.second = b;
    return m;
  };
  EXPECT_TRUE(detail::merges_join_linked_clusters(graph, {}));
  EXPECT_TRUE(detail::merges_join_linked_clusters(graph, std::vector{merge(0, 1), merge(2, 3)}));
  // Node 4 is {0, 1}, node 5 {2, 3}; {0, 1} and {2, 3} are linked by 1–2.
  EXPECT_TRUE(detail::merges_join_linked_clusters(
      graph, std::vector{merge(0, 1), merge(2, 3), merge(4, 5)}));
  EXPECT_FALSE(detail::merges_join_linked_clusters(graph, std::vector{merge(0, 2)}));
  EXPECT_FALSE(detail::merges_join_linked_clusters(graph, std::vector{merge(0, 1), merge(3, 4)}));
}

// Duplicate faces make non-manifold edges, whose triangles the whole mesh and a region chain in
// different orders; uniform weights count other valences in a region than in the whole mesh.
TEST(HierarchyRegions, HandlesNonManifoldEdgesAndUniformWeights) {
  const Mesh shape = large_shape("box_with_hole", 0.002).mesh;
  std::vector<Triangle> triangles = shape.triangles;
  for (std::size_t t = 0; t < shape.triangles.size(); t += 7) {
    const Triangle& copied = shape.triangles[t];
    triangles.push_back({copied[0], copied[2], copied[1]});
  }
  const auto mesh = std::make_shared<const Mesh>(Mesh::from_triangles(shape.positions, triangles));
  for (const VertexWeights weights : {VertexWeights::Area, VertexWeights::Uniform}) {
    HierarchyOptions options = in_regions(2, 1);
    options.weights = weights;
    const Hierarchy tree = build_hierarchy(mesh, options);
    EXPECT_NO_THROW(
        Hierarchy(mesh, options, std::vector<Merge>(tree.merges().begin(), tree.merges().end())));
    options.threads = 2;
    EXPECT_EQ(serialize_tree(build_hierarchy(mesh, options)), serialize_tree(tree));
  }
}

// A region may be too small for the geometric range a whole mesh must span (here every face of
// one region lies within 1e-33 of the origin): the exact order then, not an error.
TEST(HierarchyRegions, ARegionOutsideTheGeometricRangeFallsBackToTheExactOrder) {
  GroundTruthShape shape = large_shape("box_with_hole", 0.002);
  for (Vec3& p : shape.mesh.positions) p[0] += 10;
  const std::uint32_t strip = shape.mesh.face_count() + 100;  // more than half the faces
  std::vector<Vec3> positions;
  std::vector<Triangle> triangles;
  for (std::uint32_t i = 0; i < strip + 2; ++i)
    positions.push_back({1e-38 * i, 1e-38 * (i % 2), 0});
  for (std::uint32_t i = 0; i < strip; ++i) triangles.push_back({i, i + 1, i + 2});
  const auto mesh = std::make_shared<const Mesh>(testing::concatenated(
      {Mesh::from_triangles(std::move(positions), std::move(triangles)), shape.mesh}));
  EXPECT_EQ(serialize_tree(build_hierarchy(mesh, in_regions(2))),
            serialize_tree(build_hierarchy(mesh)));
}

TEST(HierarchyRegions, OneRegionOrASmallMeshIsTheExactOrder) {
  const auto mesh = std::make_shared<const Mesh>(large_shape("box_with_boss", 0.002).mesh);
  const std::string exact = serialize_tree(build_hierarchy(mesh));
  EXPECT_EQ(serialize_tree(build_hierarchy(mesh, in_regions(1))), exact);
  EXPECT_NE(serialize_tree(build_hierarchy(mesh, in_regions(2))), exact);
  // Too few faces for two regions of kMinRegionFaces.
  const auto small = std::make_shared<const Mesh>(make_shape("box_with_boss").mesh);
  ASSERT_LT(small->face_count(), 2 * kMinRegionFaces);
  EXPECT_EQ(serialize_tree(build_hierarchy(small, in_regions(2))),
            serialize_tree(build_hierarchy(small)));
}

// The true regions of every generated shape, clean and noisy, are found as well as by the exact
// order at their true number.
TEST(HierarchyRegions, RecoversTheTrueRegionsAsWellAsTheExactOrder) {
  double exact_sum = 0, regions_sum = 0;
  int count = 0;
  std::uint64_t seed = 1;
  for (const double noise : {0.0, 0.002})
    for (const std::string& name : shape_names()) {
      const GroundTruthShape shape = large_shape(name, noise, seed++);
      const double exact =
          testing::score_at_true_count(shape, build_hierarchy(shape.mesh)).mean_iou;
      const double regions =
          testing::score_at_true_count(shape, build_hierarchy(shape.mesh, in_regions(2))).mean_iou;
      EXPECT_GE(regions, exact - 0.05) << name << " noise " << noise;
      exact_sum += exact;
      regions_sum += regions;
      ++count;
    }
  EXPECT_GE(regions_sum / count, exact_sum / count - 0.01);
}

// A real part: the levels users cut are the exact order's, or fit as well.
TEST(HierarchyRegions, FandiskLevelsFitAsWellAsTheExactOnes) {
  const auto mesh = std::make_shared<const Mesh>(read_mesh(testing::cgal_mesh("fandisk.off")));
  const Hierarchy exact = build_hierarchy(mesh);
  const Hierarchy regions = build_hierarchy(mesh, in_regions(2));
  for (std::uint32_t k = 10; k <= 300; k += 10) {
    const double ratio = level_rms(regions, k) / level_rms(exact, k);
    EXPECT_GT(ratio, 0.98) << k;
    EXPECT_LT(ratio, 1.02) << k;
  }
  for (std::uint32_t k : {5u, 10u, 20u, 50u})
    EXPECT_EQ(cut_by_count(regions, k).labels, cut_by_count(exact, k).labels) << k;
}

TEST(HierarchyRegions, RejectsNoRegionTooManyAndExactCosts) {
  const Mesh mesh = make_shape("box", {}).mesh;
  for (unsigned regions : {0u, 257u})
    EXPECT_THROW(build_hierarchy(mesh, in_regions(regions)), InvalidInputError) << regions;
  HierarchyOptions options = in_regions(2);
  options.exact_costs = true;
  EXPECT_THROW(build_hierarchy(mesh, options), InvalidInputError);
}

}  // namespace
}  // namespace primseg
