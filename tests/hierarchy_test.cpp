// The hierarchy on shapes with known answers: generated CAD-like solids, several components,
// determinism, scale invariance, and the exact-cost reference mode.
#include "primseg/hierarchy.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/primitives/primitive_fitter.hpp"
#include "primseg/shape_generator.hpp"
#include "primseg/tree_io.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using testing::score_at_true_count;
using testing::score_segmentation;
using testing::SegmentationScore;

// Plane, cylinder, sphere, cone and torus.
HierarchyOptions every_type() {
  HierarchyOptions options;
  options.primitives = testing::every_primitive_type();
  return options;
}

// Whether every region of the shape has a type of the default primitive set (cones and tori,
// which are opt-in, have their own test below).
bool fittable(const GroundTruthShape& shape) {
  const std::vector<PrimitiveType> types = HierarchyOptions{}.primitives;
  return std::all_of(shape.regions.begin(), shape.regions.end(), [&](const Primitive& p) {
    return std::find(types.begin(), types.end(), p.type) != types.end();
  });
}

// A box with a duplicate face, a zero-area face (a repeated vertex), a non-manifold fin and an
// isolated vertex.
Mesh box_with_odd_faces() {
  const Mesh box = make_shape("box", {}).mesh;
  std::vector<Vec3> positions = box.positions;
  std::vector<Triangle> triangles = box.triangles;
  const Triangle first = triangles[0];
  triangles.push_back(first);                           // duplicate
  triangles.push_back({first[0], first[1], first[0]});  // zero area, repeated vertex
  positions.push_back({9, 9, 9});                       // isolated
  positions.push_back({0.123, 5, 0.321});
  triangles.push_back(
      {first[0], first[1], static_cast<std::uint32_t>(positions.size() - 1)});  // fin
  return Mesh::from_triangles(std::move(positions), std::move(triangles));
}

struct Variant {
  Tessellation tessellation;
  std::uint64_t seed;
};

// The fixed list of shapes and seeds of the quality tests.
const Variant kVariants[] = {{Tessellation::Cad, 1},
                             {Tessellation::Cad, 2},
                             {Tessellation::Uniform, 3},
                             {Tessellation::Uniform, 4}};

ShapeOptions variant_options(const Variant& variant, double noise) {
  ShapeOptions options;
  options.tessellation = variant.tessellation;
  options.random_motion = true;
  options.seed = variant.seed;
  options.noise = noise;
  return options;
}

TEST(Hierarchy, RecoversEveryRegionOfCleanCadShapesWithTheRightType) {
  for (const Variant& variant : kVariants)
    for (const std::string& name : shape_names()) {
      const GroundTruthShape shape = make_shape(name, variant_options(variant, 0));
      if (!fittable(shape)) continue;
      const Hierarchy h = build_hierarchy(shape.mesh);
      const SegmentationScore score = score_at_true_count(shape, h);
      EXPECT_GE(score.min_iou, 0.95) << name << " seed " << variant.seed;
      EXPECT_EQ(score.type_accuracy, 1.0) << name << " seed " << variant.seed;
    }
}

TEST(Hierarchy, NoisyCadShapesKeepAMeanIouAboveNinetyPercent) {
  double sum = 0;
  int count = 0;
  for (const Variant& variant : kVariants)
    for (const std::string& name : shape_names()) {
      // Noise: 0.2% of the bounding-box diagonal, along the normals.
      const GroundTruthShape shape = make_shape(name, variant_options(variant, 0.002));
      if (!fittable(shape)) continue;
      const SegmentationScore score = score_at_true_count(shape, build_hierarchy(shape.mesh));
      EXPECT_GE(score.mean_iou, 0.8) << name << " seed " << variant.seed;
      sum += score.mean_iou;
      ++count;
    }
  EXPECT_GE(sum / count, 0.90);
}

// With cones and tori enabled, the shapes that contain them (a chamfer, a countersink, a fillet)
// are segmented with every region recovered and typed right. The CAD-style fillet of seed 1 had
// its flat top join a fragment of the fillet (min IoU 0.875) until its first wedges were fitted
// as tori (TorusFitter.WedgesOfACadFilletAreTori).
TEST(Hierarchy, ConesAndToriAreRecoveredWhenEnabled) {
  const HierarchyOptions options = every_type();
  int cones = 0, tori = 0;
  for (const Variant& variant : kVariants)
    for (const std::string& name : shape_names()) {
      const GroundTruthShape shape = make_shape(name, variant_options(variant, 0));
      const auto has = [&](PrimitiveType type) {
        return std::any_of(shape.regions.begin(), shape.regions.end(),
                           [&](const Primitive& p) { return p.type == type; });
      };
      if (!has(PrimitiveType::Cone) && !has(PrimitiveType::Torus)) continue;
      cones += has(PrimitiveType::Cone);
      tori += has(PrimitiveType::Torus);
      const SegmentationScore score =
          score_at_true_count(shape, build_hierarchy(shape.mesh, options));
      EXPECT_GE(score.min_iou, 0.95) << name << " seed " << variant.seed;
      EXPECT_EQ(score.type_accuracy, 1.0) << name << " seed " << variant.seed;
    }
  EXPECT_EQ(cones, 8);
  EXPECT_EQ(tori, 4);
}

// With tori enabled, the flat faces of noisy boxes stay planes. A torus's error is estimated from a
// sample of 32 corners, and the merge loop keeps whichever evaluation came out lowest: before the
// sample's luck was measured on the principal plane, a face of the box (seed 2), of the slanted
// box (seed 2) and of the box with a dome (seed 3) were typed tori, their sampled error half their
// plane's exact one. (`primseg eval --primitives plane,cylinder,sphere,cone,torus --refine 2`,
// noisy, 12 seeds: plane regions typed right 98.6% → 99.9%.)
TEST(Hierarchy, NoisyFlatFacesAreNotToriWhenToriAreEnabled) {
  const HierarchyOptions options = every_type();
  for (const char* name : {"box", "slanted_box", "box_with_dome"})
    for (const std::uint64_t seed : {1, 2, 3}) {
      const GroundTruthShape shape =
          make_shape(name, variant_options({Tessellation::Uniform, seed}, 0.002));
      const SegmentationScore score =
          score_at_true_count(shape, build_hierarchy(shape.mesh, options));
      EXPECT_EQ(score.type_accuracy, 1.0) << name << " seed " << seed;
    }
}

// rotor.off (libcgal-demo) has a large toroidal part: 526 of its faces lie on one torus within
// 6e-7 RMS. A torus candidate's error is sampled; when it was sampled from the union's own 32
// corners, a torus of 526 faces took four faces off its surface unseen, and at 30 clusters that
// cluster still fitted its torus at 0.0079 RMS (0.56% of the diagonal). Each part of a candidate is
// now sampled on its own (src/primitives/torus.cpp): every cluster fits within 7.2e-4.
TEST(Hierarchy, WithToriEveryClusterOfTheRotorFitsItsPrimitive) {
  const Mesh mesh = read_mesh(testing::cgal_mesh("rotor.off"));
  const HierarchyOptions options = every_type();
  const Hierarchy h = build_hierarchy(mesh, options);
  Eigen::AlignedBox3d box;
  for (const Vec3& p : mesh.positions) box.extend(Eigen::Vector3d(p[0], p[1], p[2]));
  const double diagonal = box.diagonal().norm();
  for (const ClusterReport& report : describe_clusters(h, cut_by_count(h, 30)))
    EXPECT_LT(report.rms, 1e-3 * diagonal)
        << "cluster " << report.id << " (" << to_string(report.primitive.type) << ", "
        << report.face_count << " faces)";
}

TEST(Hierarchy, IsAFullBinaryTreeWithCostsAndTypes) {
  const GroundTruthShape shape = make_shape("box_with_boss", {});
  const Hierarchy h = build_hierarchy(shape.mesh);
  const std::uint32_t f = h.face_count();
  ASSERT_EQ(h.merges().size(), f - 1);
  std::vector<int> seen(h.node_count(), 0);
  for (std::uint32_t i = 0; i < f - 1; ++i) {
    const Merge& m = h.merges()[i];
    EXPECT_LT(m.first, m.second);
    EXPECT_LT(m.second, f + i);
    ++seen[m.first];
    ++seen[m.second];
    EXPECT_EQ(m.face_count, h.face_count(m.first) + h.face_count(m.second));
    EXPECT_GE(m.cost, 0);
    EXPECT_TRUE(std::isfinite(m.cost));
    EXPECT_FALSE(m.trailing);
  }
  for (std::uint32_t node = 0; node + 1 < h.node_count(); ++node) EXPECT_EQ(seen[node], 1);
  EXPECT_EQ(h.merges().back().face_count, f);
}

TEST(Hierarchy, ComponentsAreJoinedOnlyByTrailingMergesCostedAboveAll) {
  // Two boxes side by side, not touching.
  GroundTruthShape a = make_shape("box", {}), b = make_shape("box_with_hole", {});
  Mesh mesh = a.mesh;
  const auto offset = static_cast<std::uint32_t>(mesh.positions.size());
  std::vector<Vec3> positions = mesh.positions;
  for (Vec3 p : b.mesh.positions) positions.push_back({p[0] + 10, p[1], p[2]});
  std::vector<Triangle> triangles = mesh.triangles;
  for (Triangle t : b.mesh.triangles)
    triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  mesh = Mesh::from_triangles(std::move(positions), std::move(triangles));
  const Hierarchy h = build_hierarchy(mesh);
  EXPECT_EQ(h.component_count(), 2u);
  const auto merges = h.merges();
  ASSERT_EQ(merges.size(), h.face_count() - 1);
  double highest_real = 0;
  for (std::size_t i = 0; i + 1 < merges.size(); ++i) {
    EXPECT_FALSE(merges[i].trailing);
    highest_real = std::max(highest_real, merges[i].cost);
  }
  EXPECT_TRUE(merges.back().trailing);
  EXPECT_GT(merges.back().cost, highest_real);
  // Cuts never apply the trailing merge.
  EXPECT_EQ(cut_by_count(h, 1).cluster_count(), 2u);
  const Segmentation thirteen = cut_by_count(h, 13);
  EXPECT_EQ(thirteen.cluster_count(), 13u);
  for (std::uint32_t f = 0; f < a.mesh.face_count(); ++f)
    for (std::uint32_t g = a.mesh.face_count(); g < h.face_count(); ++g)
      ASSERT_NE(thirteen.labels[f], thirteen.labels[g]);
  EXPECT_EQ(cut_by_tolerance(h, 1e300).cluster_count(), 2u);
}

TEST(Hierarchy, SameInputGivesTheSameTreeBitForBit) {
  const Mesh mesh = testing::noisy_uniform_shape("box_with_dome");
  const std::string first = serialize_tree(build_hierarchy(mesh));
  const std::string second = serialize_tree(build_hierarchy(mesh));
  EXPECT_EQ(first, second);
}

// Both ways the merge loop uses threads: with closed-form types a merge's few jobs stay on the
// calling thread (only the first evaluation and large sets are shared); with cones and tori every
// merge's jobs are shared.
TEST(Hierarchy, AnyThreadCountGivesTheSameTreeBitForBit) {
  for (const bool costly_fits : {false, true}) {
    SCOPED_TRACE(costly_fits ? "every type" : "default types");
    ShapeOptions options;
    options.tessellation = Tessellation::Uniform;
    // About 10k faces, enough work for every thread; 2.5k with the costly fits.
    options.edge_length = costly_fits ? 0.04 : 0.02;
    options.noise = 0.002;
    options.random_motion = true;
    const GroundTruthShape shape = make_shape("box_with_boss", options);
    HierarchyOptions one_thread = costly_fits ? every_type() : HierarchyOptions{};
    one_thread.threads = 1;
    const std::string reference = serialize_tree(build_hierarchy(shape.mesh, one_thread));
    for (unsigned threads : {2u, 3u, 0u}) {
      HierarchyOptions parallel = one_thread;
      parallel.threads = threads;
      EXPECT_EQ(serialize_tree(build_hierarchy(shape.mesh, parallel)), reference) << threads;
    }
    // Threads the system refuses to start (a process limit): the work runs on the others.
    const testing::RefuseNewThreads refused;
    for (unsigned threads : {2u, 100000u}) {
      HierarchyOptions parallel = one_thread;
      parallel.threads = threads;
      EXPECT_EQ(serialize_tree(build_hierarchy(shape.mesh, parallel)), reference) << threads;
    }
  }
}

// The tree depends on the geometry and the order of the faces only: the same triangles listed
// from another corner (orientation kept), with their vertices numbered otherwise, give the same
// merges bit for bit. Every sum over a triangle's corners starts at the same one
// (DualGraph::corners) and an edge's concavity is judged from its midpoint. Before, the
// round-off of another start settled the ties of symmetric parts otherwise: rotating the corners
// of every other triangle changed some level from K = 2 to 50 on 19 meshes of libcgal-demo
// (among them the icosahedron and the ellipsoid below), and renumbering fandisk's vertices
// changed its merges.
TEST(Hierarchy, RenumberedVerticesAndRotatedCornersGiveTheSameTree) {
  using testing::same_bits;
  struct Case {
    std::string what;
    Mesh mesh;
    HierarchyOptions options;
  };
  HierarchyOptions uniform;
  uniform.weights = VertexWeights::Uniform;
  const HierarchyOptions five_types = every_type();  // the torus's fit reads a sample of corners
  ShapeOptions noisy;
  noisy.tessellation = Tessellation::Uniform;
  noisy.noise = 0.002;
  const std::vector<Case> cases = {
      {"fandisk", read_mesh(testing::cgal_mesh("fandisk.off")), {}},
      {"icosahedron", read_mesh(testing::cgal_mesh("icosahedron.off")), {}},
      {"ellipsoid, uniform weights", read_mesh(testing::cgal_mesh("ellipsoid.off")), uniform},
      {"noisy filleted cylinder, five types", make_shape("filleted_cylinder", noisy).mesh,
       five_types}};
  for (const Case& c : cases) {
    const Hierarchy reference = build_hierarchy(c.mesh, c.options);
    for (const bool renumber : {false, true}) {
      SCOPED_TRACE(c.what + (renumber ? ", vertices renumbered" : ", corners rotated"));
      std::vector<std::uint32_t> new_index(c.mesh.vertex_count());
      std::iota(new_index.begin(), new_index.end(), 0u);
      if (renumber) std::shuffle(new_index.begin(), new_index.end(), std::mt19937_64(2006));
      std::vector<Triangle> triangles = c.mesh.triangles;
      for (std::size_t t = 0; t < triangles.size(); ++t) {
        Triangle& tri = triangles[t];
        for (std::uint32_t& v : tri) v = new_index[v];
        if (t % 3 == 1) tri = {tri[1], tri[2], tri[0]};
        if (t % 3 == 2) tri = {tri[2], tri[0], tri[1]};
      }
      std::vector<Vec3> positions(c.mesh.vertex_count());
      for (std::uint32_t v = 0; v < c.mesh.vertex_count(); ++v)
        positions[new_index[v]] = c.mesh.positions[v];
      const Hierarchy h = build_hierarchy(
          Mesh::from_triangles(std::move(positions), std::move(triangles)), c.options);
      ASSERT_EQ(h.merges().size(), reference.merges().size());
      for (std::size_t i = 0; i < h.merges().size(); ++i) {
        const Merge& got = h.merges()[i];
        const Merge& want = reference.merges()[i];
        ASSERT_EQ(got.first, want.first) << "merge " << i;
        ASSERT_EQ(got.second, want.second) << "merge " << i;
        ASSERT_TRUE(same_bits(got.cost, want.cost)) << "merge " << i;
        ASSERT_TRUE(same_bits(got.error, want.error)) << "merge " << i;
        ASSERT_TRUE(same_bits(got.weight, want.weight)) << "merge " << i;
        ASSERT_EQ(got.primitive.type, want.primitive.type) << "merge " << i;
        ASSERT_TRUE(same_bits(got.primitive.radius, want.primitive.radius)) << "merge " << i;
      }
    }
  }
}

// HierarchyOptions::face_order: the merge loop on the graph in spatial order makes the
// same tree, bit for bit (serialize_tree writes every merge's ids, costs, errors, weights and
// primitive), in each mode of the loop and on input with polygons, non-manifold edges, degenerate
// and duplicate faces and several components; faces listed in random order included.
TEST(Hierarchy, TheGraphInSpatialOrderGivesTheSameTreeBitForBit) {
  struct Case {
    std::string what;
    Mesh mesh;
    HierarchyOptions options;
  };
  ShapeOptions noisy;
  noisy.tessellation = Tessellation::Uniform;
  noisy.noise = 0.002;
  noisy.random_motion = true;
  const Mesh fandisk = read_mesh(testing::cgal_mesh("fandisk.off"));
  const Mesh shaft = make_shape("chamfered_cylinder", noisy).mesh;
  HierarchyOptions uniform, eager, exact, batched, one_thread, cones;
  uniform.weights = VertexWeights::Uniform;
  eager.evaluation = CandidateEvaluation::Eager;
  exact.exact_costs = true;
  batched.merge_batch_tolerance = 0.1;
  one_thread.threads = 1;
  cones.primitives = {PrimitiveType::Plane, PrimitiveType::Cylinder, PrimitiveType::Sphere,
                      PrimitiveType::Cone};

  // The faces in random order, and a polygon mesh: a grid of quads on a cylinder, closed by two
  // polygons of 40 corners (more triangles than a face's corners are read for).
  std::vector<std::uint32_t> order(fandisk.face_count());
  std::iota(order.begin(), order.end(), 0u);
  std::shuffle(order.begin(), order.end(), std::mt19937_64(67));
  std::vector<Triangle> shuffled(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) shuffled[i] = fandisk.triangles[order[i]];
  std::vector<Vec3> ring;
  const int around = 40, rows = 12;
  for (int i = 0; i <= rows; ++i)
    for (int j = 0; j < around; ++j) {
      const double angle = 2 * M_PI * j / around;
      ring.push_back({std::cos(angle), std::sin(angle), 0.1 * i + 0.01 * std::sin(3.0 * j + i)});
    }
  std::vector<std::uint32_t> offsets{0}, corners;
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>(i * around + j % around); };
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < around; ++j) {
      corners.insert(corners.end(), {id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)});
      offsets.push_back(static_cast<std::uint32_t>(corners.size()));
    }
  for (int j = around; j-- > 0;) corners.push_back(id(0, j));
  offsets.push_back(static_cast<std::uint32_t>(corners.size()));
  for (int j = 0; j < around; ++j) corners.push_back(id(rows, j));
  offsets.push_back(static_cast<std::uint32_t>(corners.size()));

  const std::vector<Case> cases = {
      {"fandisk", fandisk, {}},
      {"fandisk, faces shuffled", Mesh::from_triangles(fandisk.positions, shuffled), {}},
      {"fandisk, uniform weights", fandisk, uniform},
      {"fandisk, eager", fandisk, eager},
      {"fandisk, batched", fandisk, batched},
      {"fandisk, one thread", fandisk, one_thread},
      {"noisy chamfered cylinder, cones", shaft, cones},
      {"noisy chamfered cylinder, exact costs", shaft, exact},
      {"polygons", Mesh::from_polygons(ring, offsets, corners), {}},
      {"odd faces, two components", testing::concatenated({box_with_odd_faces(), shaft}), {}}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    HierarchyOptions as_listed = c.options, in_spatial_order = c.options;
    as_listed.face_order = FaceOrder::AsListed;
    in_spatial_order.face_order = FaceOrder::Spatial;
    EXPECT_EQ(serialize_tree(build_hierarchy(c.mesh, in_spatial_order)),
              serialize_tree(build_hierarchy(c.mesh, as_listed)));
  }
}

TEST(Hierarchy, ScalingByAPowerOfTwoKeepsEveryMergeAndLabel) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.noise = 0.002;
  options.random_motion = true;
  const GroundTruthShape shape = make_shape("cylinder_with_sphere_cap", options);
  const Hierarchy reference = build_hierarchy(shape.mesh);
  // 2^±100 is about 1e±30, near both ends of the range the geometry accepts
  // (check_geometric_range; tests/units_test.cpp checks the other operations).
  for (int exponent : {-100, -37, 11, 100}) {
    Mesh scaled = shape.mesh;
    for (Vec3& p : scaled.positions)
      for (double& x : p) x = std::ldexp(x, exponent);
    const Hierarchy h = build_hierarchy(scaled);
    ASSERT_EQ(h.merges().size(), reference.merges().size());
    for (std::size_t i = 0; i < h.merges().size(); ++i) {
      EXPECT_EQ(h.merges()[i].first, reference.merges()[i].first) << "exponent " << exponent;
      EXPECT_EQ(h.merges()[i].second, reference.merges()[i].second);
      EXPECT_EQ(h.merges()[i].cost, reference.merges()[i].cost);
    }
    for (std::uint32_t k : {1u, 3u, 10u, 100u})
      EXPECT_EQ(cut_by_count(h, k).labels, cut_by_count(reference, k).labels);
    // Parameters are reported in input units.
    const Primitive p = h.primitive(h.node_count() - 2),
                    q = reference.primitive(reference.node_count() - 2);
    EXPECT_EQ(p.radius, std::ldexp(q.radius, exponent));
  }
}

TEST(Hierarchy, ExactCostModeAgreesWithTheConstantTimeCostsOnCleanShapes) {
  HierarchyOptions exact;
  exact.exact_costs = true;
  for (const std::string name : {"box_with_hole", "capped_cylinder", "box_with_dome"}) {
    const GroundTruthShape shape = make_shape(name, {});
    const Hierarchy fast = build_hierarchy(shape.mesh);
    const Hierarchy slow = build_hierarchy(shape.mesh, exact);
    const auto k = static_cast<std::uint32_t>(shape.regions.size());
    EXPECT_EQ(cut_by_count(fast, k).labels, cut_by_count(slow, k).labels) << name;
    EXPECT_GE(score_at_true_count(shape, slow).min_iou, 0.95) << name;
  }
}

TEST(Hierarchy, DegenerateAndNonManifoldInputIsHandled) {
  const Mesh mesh = box_with_odd_faces();
  const Hierarchy h = build_hierarchy(mesh);
  EXPECT_EQ(h.merges().size(), h.face_count() - 1);
  EXPECT_EQ(h.component_count(), 1u);
  for (std::uint32_t k = 1; k <= h.face_count(); ++k) {
    const Segmentation seg = cut_by_count(h, k);
    EXPECT_EQ(seg.cluster_count(), k);
    for (const ClusterReport& r : describe_clusters(h, seg)) {
      EXPECT_TRUE(std::isfinite(r.rms));
      EXPECT_TRUE(std::isfinite(r.primitive.radius));
    }
  }
}

TEST(Hierarchy, ManyFacesOnOneEdgeGiveLinearlyManyDualEdges) {
  // A fan of 2000 triangles all sharing the edge (0, 1).
  std::vector<Vec3> positions{{0, 0, 0}, {1, 0, 0}};
  std::vector<Triangle> triangles;
  for (int i = 0; i < 2000; ++i) {
    const double angle = 2 * M_PI * i / 2000;
    positions.push_back({0.5, std::cos(angle), std::sin(angle)});
    triangles.push_back({0, 1, static_cast<std::uint32_t>(positions.size() - 1)});
  }
  const Mesh mesh = Mesh::from_triangles(std::move(positions), std::move(triangles));
  const DualGraph graph(mesh, VertexWeights::Area);
  EXPECT_EQ(graph.edges().size(), 1999u);
  EXPECT_EQ(graph.component_count(), 1u);
  const Hierarchy h = build_hierarchy(mesh);
  EXPECT_EQ(h.merges().size(), 1999u);
}

TEST(HierarchyBuilder, SteppingGivesTheOneShotTree) {
  const GroundTruthShape shape = make_shape("box_with_blind_hole", {});
  auto mesh = std::make_shared<const Mesh>(shape.mesh);
  HierarchyBuilder builder(mesh);
  EXPECT_EQ(builder.total_merge_count(), mesh->face_count() - 1);
  std::uint32_t steps = 0;
  while (builder.step()) EXPECT_EQ(builder.merge_count(), ++steps);
  EXPECT_EQ(steps, builder.total_merge_count());
  std::vector<double> progress;
  const Hierarchy stepped = builder.finish([&](double f) { progress.push_back(f); });
  EXPECT_EQ(serialize_tree(stepped), serialize_tree(build_hierarchy(shape.mesh)));
  ASSERT_FALSE(progress.empty());
  EXPECT_EQ(progress.back(), 1.0);
  EXPECT_THROW(builder.finish(), Error);
}

// A build stopped early hands over its merges so far: the one-shot tree's first ones.
TEST(HierarchyBuilder, TakeMergesEndsTheBuildWithTheMergesSoFar) {
  const GroundTruthShape shape = make_shape("box_with_blind_hole", {});
  auto mesh = std::make_shared<const Mesh>(shape.mesh);
  const Hierarchy whole = build_hierarchy(mesh);
  HierarchyBuilder builder(mesh);
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(builder.step());
  const std::vector<Merge> taken = builder.take_merges();
  ASSERT_EQ(taken.size(), 100u);
  for (std::size_t i = 0; i < taken.size(); ++i) {
    EXPECT_EQ(taken[i].first, whole.merges()[i].first) << i;
    EXPECT_EQ(taken[i].second, whole.merges()[i].second) << i;
    EXPECT_EQ(taken[i].cost, whole.merges()[i].cost) << i;
  }
  EXPECT_THROW(builder.step(), Error);
  EXPECT_THROW((void)builder.merge_count(), Error);
  EXPECT_THROW((void)builder.merges(), Error);
  EXPECT_THROW(builder.take_merges(), Error);
  EXPECT_THROW(builder.finish(), Error);

  HierarchyBuilder finished(mesh);
  (void)finished.finish();
  EXPECT_THROW(finished.take_merges(), Error);
}

TEST(Hierarchy, LinkageKeepsTheRawCostsThatScipyLinkageMakesMonotone) {
  ShapeOptions noisy;
  noisy.noise = 0.004;
  const Hierarchy h = build_hierarchy(make_shape("box_with_boss", noisy).mesh);
  const std::vector<std::array<double, 4>> raw = h.linkage();
  const std::vector<std::array<double, 4>> scipy = scipy_linkage(h);
  ASSERT_EQ(raw.size(), h.face_count() - 1);
  ASSERT_EQ(scipy.size(), raw.size());
  std::size_t drops = 0;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const Merge& m = h.merges()[i];
    EXPECT_EQ(raw[i], (std::array<double, 4>{double(m.first), double(m.second), m.cost,
                                             double(m.face_count)}));
    // The same children and sizes; a height at least the raw cost, above the previous one.
    EXPECT_EQ(scipy[i][0], raw[i][0]);
    EXPECT_EQ(scipy[i][1], raw[i][1]);
    EXPECT_EQ(scipy[i][3], raw[i][3]);
    EXPECT_GE(scipy[i][2], raw[i][2]);
    if (i > 0) {
      EXPECT_GT(scipy[i][2], scipy[i - 1][2]);
      drops += raw[i][2] < raw[i - 1][2];
    }
  }
  EXPECT_GT(drops, 0u);  // greedy costs do drop after some merges: why the two differ

  // A tree whose merges do not match its mesh is refused.
  std::vector<Merge> merges(h.merges().begin(), h.merges().end());
  merges.pop_back();
  EXPECT_THROW(Hierarchy(h.shared_mesh(), h.options(), merges), InvalidInputError);
}

TEST(Hierarchy, SingleFaceMeshHasNoMerges) {
  const Mesh mesh = Mesh::from_triangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {Triangle{0, 1, 2}});
  const Hierarchy h = build_hierarchy(mesh);
  EXPECT_TRUE(h.merges().empty());
  EXPECT_EQ(cut_by_count(h, 1).labels, std::vector<std::uint32_t>{0});
  EXPECT_EQ(h.primitive(0).type, PrimitiveType::Plane);
}

TEST(Hierarchy, NodeIdsBeyondTheTreeAreRefused) {
  const Hierarchy h = build_hierarchy(make_shape("box", {}).mesh);
  const std::uint32_t root = h.node_count() - 1;
  EXPECT_EQ(h.face_count(root), h.face_count());
  for (const std::uint32_t bad : {h.node_count(), h.node_count() + 7, UINT32_MAX}) {
    EXPECT_THROW(h.primitive(bad), InvalidInputError) << bad;
    EXPECT_THROW(h.error(bad), InvalidInputError) << bad;
    EXPECT_THROW(h.weight(bad), InvalidInputError) << bad;
    EXPECT_THROW(h.face_count(bad), InvalidInputError) << bad;
    EXPECT_THROW(h.rms_estimate(bad), InvalidInputError) << bad;
  }
  // A hand-made segmentation naming such a node is refused too, before any fit.
  Segmentation cut = cut_by_count(h, 6);
  cut.nodes[2] = h.node_count();
  EXPECT_THROW(describe_clusters(h, cut), InvalidInputError);
}

TEST(Hierarchy, InvalidOptionsAreRejected) {
  const Mesh mesh = make_shape("box", {}).mesh;
  HierarchyOptions none;
  none.primitives.clear();
  EXPECT_THROW(build_hierarchy(mesh, none), InvalidInputError);
  HierarchyOptions twice;
  twice.primitives = {PrimitiveType::Plane, PrimitiveType::Plane};
  EXPECT_THROW(build_hierarchy(mesh, twice), InvalidInputError);
  HierarchyOptions negative;
  negative.type_penalty[1] = -1;
  EXPECT_THROW(build_hierarchy(mesh, negative), InvalidInputError);
}

TEST(Hierarchy, SinglePrimitiveTypesStillBuildATree) {
  const GroundTruthShape shape = make_shape("capped_cylinder", {});
  for (PrimitiveType type :
       {PrimitiveType::Plane, PrimitiveType::Cylinder, PrimitiveType::Sphere}) {
    HierarchyOptions options;
    options.primitives = {type};
    const Hierarchy h = build_hierarchy(shape.mesh, options);
    EXPECT_EQ(h.merges().size(), h.face_count() - 1);
    // The cylinder is found whenever cylinders are allowed.
    if (type == PrimitiveType::Cylinder) {
      bool found = false;
      for (const ClusterReport& r : describe_clusters(h, cut_by_count(h, 3)))
        found |= r.primitive.type == PrimitiveType::Cylinder && r.rms < 1e-9;
      EXPECT_TRUE(found);
    }
  }
}

TEST(Hierarchy, FandiskCutsGiveConnectedClustersAndFlatFacesArePlanes) {
  const Mesh mesh = read_mesh(testing::cgal_mesh("fandisk.off"));
  const Hierarchy h = build_hierarchy(mesh);
  ASSERT_EQ(h.face_count(), 12946u);
  // Face adjacency for the connectivity check.
  const DualGraph& graph = h.graph();
  for (std::uint32_t k : {10u, 25u, 60u, 200u}) {
    const Segmentation seg = cut_by_count(h, k);
    ASSERT_EQ(seg.cluster_count(), k);
    std::vector<std::uint32_t> parent(h.face_count());
    std::iota(parent.begin(), parent.end(), 0u);
    auto find = [&](std::uint32_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (const DualEdge& e : graph.edges())
      if (seg.labels[e.first] == seg.labels[e.second]) parent[find(e.first)] = find(e.second);
    std::vector<std::uint32_t> root_of_label(k, UINT32_MAX);
    for (std::uint32_t f = 0; f < h.face_count(); ++f) {
      std::uint32_t& root = root_of_label[seg.labels[f]];
      if (root == UINT32_MAX) root = find(f);
      EXPECT_EQ(root, find(f)) << "cluster " << seg.labels[f] << " of K=" << k << " is split";
    }
  }
  // Fandisk's large flat faces: every cluster at K=25 that a plane fits to 1e-9 of the diagonal
  // is reported as a plane, and the largest cluster is flat.
  const Segmentation seg = cut_by_count(h, 25);
  const auto reports = describe_clusters(h, seg);
  int planes = 0;
  for (const ClusterReport& r : reports) planes += r.primitive.type == PrimitiveType::Plane;
  EXPECT_GE(planes, 8);
  EXPECT_EQ(reports[0].primitive.type, PrimitiveType::Plane);
  EXPECT_LT(reports[0].max, 1e-9 * bounding_box_diagonal(mesh));
}

}  // namespace
}  // namespace primseg
