// The error curve and the automatic level on shapes whose number of regions is known.
#include "primseg/auto_level.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "primseg/cut.hpp"
#include "primseg/dual_graph.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

TEST(ErrorCurve, IsTheRmsOfEveryCutByCount) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.noise = 0.002;
  const GroundTruthShape shape = make_shape("box_with_boss", options);
  const Hierarchy h = build_hierarchy(shape.mesh);
  const std::vector<ErrorCurvePoint> curve = error_curve(h);
  ASSERT_EQ(curve.size(), h.face_count() - h.component_count() + 1);
  EXPECT_EQ(curve.front().clusters, h.component_count());
  EXPECT_EQ(curve.back().clusters, h.face_count());
  EXPECT_EQ(curve.back().rms, 0.0) << "single triangles fit their plane exactly";
  double total_weight = 0;
  for (std::uint32_t f = 0; f < h.face_count(); ++f) total_weight += h.weight(f);
  const double scale = std::ldexp(1.0, h.graph().frame().exponent);
  for (std::uint32_t k : {1u, 2u, 8u, 9u, 40u, 500u}) {
    const Segmentation s = cut_by_count(h, k);
    double error = 0;
    for (std::uint32_t node : s.nodes) error += h.error(node);
    const double expected = std::sqrt(error / total_weight) * scale;
    EXPECT_NEAR(curve[k - 1].rms, expected, 1e-9 * expected + 1e-15) << "K = " << k;
    EXPECT_EQ(curve[k - 1].clusters, k);
  }
}

// The target: on the generated data set (every shape, CAD, uniform and noisy variants,
// random rigid motions) the chosen K is the true number of regions on >= 80% of the shapes and
// within one on >= 95%.
TEST(AutoLevel, FindsTheTrueNumberOfRegionsOfGeneratedShapes) {
  struct Variant {
    Tessellation tessellation;
    double noise;
  };
  int cases = 0, exact = 0, within_one = 0;
  for (const Variant variant :
       {Variant{Tessellation::Cad, 0.0}, Variant{Tessellation::Uniform, 0.0},
        Variant{Tessellation::Uniform, 0.002}})
    for (const std::string& name : shape_names()) {
      const GroundTruthShape shape =
          testing::moved_shape_truth(name, variant.tessellation, 7, variant.noise);
      const AutoLevel level = choose_level(build_hierarchy(shape.mesh));
      const auto truth = static_cast<std::uint32_t>(shape.regions.size());
      ++cases;
      exact += level.clusters == truth;
      within_one += level.clusters + 1 >= truth && level.clusters <= truth + 1;
      ASSERT_FALSE(level.candidates.empty());
      bool listed = false;
      for (const LevelCandidate& c : level.candidates) listed |= c.clusters == level.clusters;
      EXPECT_TRUE(listed) << name << ": the chosen level is among the candidates";
    }
  EXPECT_GE(exact, 0.8 * cases) << exact << " of " << cases;
  EXPECT_GE(within_one, 0.95 * cases) << within_one << " of " << cases;
}

TEST(AutoLevel, ExactPlaneCylinderSphereShapesGetTheirTrueCount) {
  for (const std::string name : {"box", "slanted_box", "capped_cylinder", "sphere", "box_with_hole",
                                 "box_with_dome", "stepped_block"}) {
    const GroundTruthShape shape = make_shape(name);
    const Hierarchy h = build_hierarchy(shape.mesh);
    const AutoLevel level = choose_level(h);
    EXPECT_EQ(level.clusters, shape.regions.size()) << name;
    // "At least min_score": a threshold equal to the chosen jump's score still keeps it.
    if (level.rule != AutoLevelRule::Jump) continue;
    AutoLevelOptions exactly;
    for (const LevelCandidate& c : level.candidates)
      if (c.clusters == level.clusters) exactly.min_score = c.score;
    ASSERT_GT(exactly.min_score, 2.0) << name;
    EXPECT_EQ(choose_level(h, exactly).clusters, level.clusters) << name;
  }
}

// The clean CAD chamfered cylinder with every primitive type: its top's fan and the chamfer, all
// of whose vertices lie on two circles, once merged into a torus of RMS 1e-16 on seeds 2 and 4,
// and the automatic level chose 3 regions.
TEST(AutoLevel, ACadChamferAndTheTopItBevelsStayTwoRegionsWithEveryType) {
  HierarchyOptions options;
  options.primitives = testing::every_primitive_type();
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const GroundTruthShape shape =
        testing::moved_shape_truth("chamfered_cylinder", Tessellation::Cad, seed, 0.0);
    const Hierarchy h = build_hierarchy(shape.mesh, options);
    EXPECT_EQ(choose_level(h).clusters, shape.regions.size()) << "seed " << seed;
  }
}

// A small region joining its neighbour raises the RMS of a noisy level by far less than twice
// (1.3 to 1.9 here), while the cluster it makes fits two to four times worse than the level: a
// chamfer, a fillet, a countersink, the dome's sphere and the slanted face, with cones and tori
// enabled (tori can bend over two of these surfaces at once). Without cluster jumps the level
// before the region joins was found in 1 of these 10 cases.
TEST(AutoLevel, ASmallRegionJoiningItsNeighbourIsAJumpOfTheMergedCluster) {
  int found = 0, found_by_level_alone = 0, by_merge_score = 0, cases = 0;
  for (const char* name : {"slanted_box", "box_with_dome", "chamfered_cylinder",
                           "filleted_cylinder", "box_with_countersink"})
    for (std::uint64_t seed = 1; seed <= 2; ++seed) {
      const GroundTruthShape shape = testing::noisy_uniform_truth(name, seed, 0.002);
      HierarchyOptions hierarchy_options;
      hierarchy_options.primitives = testing::every_primitive_type();
      const Hierarchy h = build_hierarchy(shape.mesh, hierarchy_options);
      const AutoLevel level = choose_level(h);
      AutoLevelOptions level_alone;
      level_alone.cluster_jumps = false;
      const auto truth = static_cast<std::uint32_t>(shape.regions.size());
      ++cases;
      found += level.clusters == truth;
      found_by_level_alone += choose_level(h, level_alone).clusters == truth;
      for (const LevelCandidate& c : level.candidates) {
        if (c.clusters != level.clusters || c.score >= AutoLevelOptions{}.min_score) continue;
        ++by_merge_score;
        EXPECT_GE(c.merge_score, AutoLevelOptions{}.min_score) << name << " seed " << seed;
      }
    }
  EXPECT_GE(found, cases - 1) << found << " of " << cases;
  EXPECT_LE(found_by_level_alone, cases / 2) << "the cases must need the rule";
  EXPECT_GE(by_merge_score, cases / 2) << "chosen by the merged cluster's jump";
}

// oblong.off of libcgal-demo, a CAD part: the level's score alone chose 30 clusters, three of
// which straddle two surfaces; the next merge after 40 clusters, every one of them fitting,
// makes a cluster 5.7 times the level's RMS (though the level's RMS rises by 1.7 only).
TEST(AutoLevel, ACadPartIsCutWhereEveryClusterFits) {
  const Hierarchy oblong = build_hierarchy(read_mesh(testing::cgal_mesh("oblong.off")));
  const AutoLevel level = choose_level(oblong);
  AutoLevelOptions level_alone;
  level_alone.cluster_jumps = false;
  const AutoLevel before = choose_level(oblong, level_alone);
  EXPECT_EQ(level.rule, AutoLevelRule::Jump);
  EXPECT_EQ(level.clusters, 40u);
  EXPECT_EQ(before.clusters, 30u);
  auto worst_rms = [&](std::uint32_t k) {
    double worst = 0;
    for (const ClusterReport& c : describe_clusters(oblong, cut_by_count(oblong, k)))
      worst = std::max(worst, c.rms);
    return worst;
  };
  const double diagonal = bounding_box_diagonal(oblong.mesh());
  EXPECT_LT(worst_rms(level.clusters), 0.001 * diagonal);   // 0.036%
  EXPECT_GT(worst_rms(before.clusters), 0.003 * diagonal);  // 0.45%
}

// merge_score is the RMS of the cluster the level's next merge makes over the level's RMS, the
// latter at least 0.1% of the bounding-box diagonal.
TEST(AutoLevel, TheMergeScoreIsTheMergedClustersRmsOverTheLevels) {
  const GroundTruthShape shape = testing::noisy_uniform_truth("box_with_boss", 1, 0.002);
  const Hierarchy h = build_hierarchy(shape.mesh);
  AutoLevelOptions all;
  all.max_candidates = h.face_count();
  const AutoLevel level = choose_level(h, all);
  const std::vector<ErrorCurvePoint> curve = error_curve(h);
  const double floor = 1e-3 * bounding_box_diagonal(shape.mesh);
  const std::uint32_t f = h.face_count();
  int checked = 0;
  for (const LevelCandidate& c : level.candidates) {
    if (c.clusters == 1) {
      EXPECT_EQ(c.merge_score, 0.0);
      continue;
    }
    // The merge that takes level K to K - 1 is the (F - K + 1)-th; its node is F + F - K.
    const double expected =
        h.rms_estimate(f + (f - c.clusters)) / std::max(curve[c.clusters - 1].rms, floor);
    EXPECT_NEAR(c.merge_score, expected, 1e-12 * expected) << "K = " << c.clusters;
    ++checked;
  }
  EXPECT_GE(checked, 100);
}

// Real CAD parts with blends have no jump of 2 (fandisk's best score is 1.56): the curve falls
// steadily while merges join different surfaces and flattens at about 25 clusters, where the
// clean fandisk's segmentation is whole surfaces (snapping noisy vertices onto its level 25 lowers
// their distance to the clean mesh 5x, onto level 20 only 1.7x). The knee lies there.
TEST(AutoLevel, RealPartsWithoutAJumpGetTheKneeOfTheCurve) {
  const Hierarchy fandisk = build_hierarchy(read_mesh(testing::cgal_mesh("fandisk.off")));
  const AutoLevel level = choose_level(fandisk);
  EXPECT_EQ(level.rule, AutoLevelRule::Knee);
  EXPECT_GE(level.clusters, 25u);
  EXPECT_LE(level.clusters, 40u);
  bool listed = false;
  for (const LevelCandidate& c : level.candidates) listed |= c.clusters == level.clusters;
  EXPECT_TRUE(listed);

  AutoLevelOptions no_knee;
  no_knee.knee_fallback = false;
  const AutoLevel components = choose_level(fandisk, no_knee);
  EXPECT_EQ(components.rule, AutoLevelRule::Components);
  EXPECT_EQ(components.clusters, 1u);
}

// Levels finer than F / 2 are left out, except an exact one far above noise: a polyhedron whose
// every face is a plane of its own (F / 2 would give a tetrahedron one or two clusters).
TEST(AutoLevel, SmallPolyhedraGetOneClusterPerFace) {
  const std::vector<Vec3> tetrahedron{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}};
  const std::vector<Vec3> octahedron{{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                     {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  // A triangular prism: two triangles and three rectangles split in two (8 triangles, 5 planes).
  const std::vector<Vec3> prism{{0, 0, 0}, {2, 0, 0}, {0, 1, 0}, {0, 0, 3}, {2, 0, 3}, {0, 1, 3}};
  struct Case {
    const char* name;
    Mesh mesh;
    std::uint32_t planes;
  };
  const std::vector<Case> cases{
      {"tetrahedron",
       Mesh::from_triangles(tetrahedron, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}), 4},
      {"octahedron",
       Mesh::from_triangles(octahedron, {{0, 2, 4},
                                         {2, 1, 4},
                                         {1, 3, 4},
                                         {3, 0, 4},
                                         {2, 0, 5},
                                         {1, 2, 5},
                                         {3, 1, 5},
                                         {0, 3, 5}}),
       8},
      {"prism",
       Mesh::from_triangles(prism, {{0, 2, 1},
                                    {3, 4, 5},
                                    {0, 1, 4},
                                    {0, 4, 3},
                                    {1, 2, 5},
                                    {1, 5, 4},
                                    {2, 0, 3},
                                    {2, 3, 5}}),
       5},
  };
  for (const Case& c : cases) {
    const Hierarchy h = build_hierarchy(c.mesh);
    const AutoLevel level = choose_level(h);
    EXPECT_EQ(level.clusters, c.planes) << c.name;
    EXPECT_EQ(level.rule, AutoLevelRule::Jump) << c.name;
    EXPECT_GT(level.clusters, h.face_count() / 2) << c.name;
  }
}

// A curve that only wavers has a best split too, but no bend: one noisy sphere stays one cluster.
TEST(AutoLevel, ANoisySingleSurfaceHasNoKnee) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.noise = 0.002;
  options.random_motion = true;
  for (const std::uint64_t seed : {1, 2, 3}) {
    options.seed = seed;
    const AutoLevel level = choose_level(build_hierarchy(make_shape("sphere", options).mesh));
    EXPECT_EQ(level.clusters, 1u) << "seed " << seed;
    EXPECT_EQ(level.rule, AutoLevelRule::Components) << "seed " << seed;
  }
}

// A hierarchy whose error curve is `rms` (rms[K − 1] for K clusters, input units, K < F): a strip
// of F triangles merged one at a time in a chain, each merge given the error that makes its
// level's RMS the one asked for (the curve only reads the merges' errors and the faces' weights).
Hierarchy hierarchy_with_curve(const std::vector<double>& rms, std::uint32_t faces) {
  std::vector<Vec3> positions;
  for (std::uint32_t i = 0; i < faces / 2 + 1; ++i) {
    positions.push_back({double(i), 0, 0});
    positions.push_back({double(i), 1, 0});
  }
  std::vector<Triangle> triangles;
  for (std::uint32_t t = 0; t < faces; ++t) {
    const std::uint32_t i = t / 2;
    triangles.push_back(t % 2 == 0 ? Triangle{2 * i, 2 * i + 2, 2 * i + 1}
                                   : Triangle{2 * i + 1, 2 * i + 2, 2 * i + 3});
  }
  const auto mesh = std::make_shared<const Mesh>(
      Mesh::from_triangles(std::move(positions), std::move(triangles)));
  // Each face's weight (working frame), as the tree's parts must add them up.
  const DualGraph graph(*mesh, VertexWeights::Area);
  std::vector<double> face_weight(faces, 0);
  for (std::uint32_t f = 0; f < faces; ++f)
    for (const double w : graph.corner_weights(graph.first_triangle(f))) face_weight[f] += w;
  double total_weight = 0;
  for (const double w : face_weight) total_weight += w;
  const int exponent = graph.frame().exponent;
  std::vector<Merge> merges(faces - 1);
  double chain_weight = face_weight[0];
  for (std::uint32_t m = 0; m + 1 < faces; ++m) {
    // After m + 1 merges the level has K = F − m − 1 clusters: the chain and single faces.
    const std::uint32_t k = faces - m - 1;
    const double level_rms = k <= rms.size() ? rms[k - 1] : rms.back();
    Merge& merge = merges[m];
    merge.first = m + 1;
    merge.second = m == 0 ? 0 : faces + m - 1;
    if (merge.first > merge.second) std::swap(merge.first, merge.second);
    merge.error = total_weight * std::pow(std::ldexp(level_rms, -exponent), 2);
    merge.cost = merge.error;
    merge.weight = chain_weight += face_weight[m + 1];
    merge.face_count = m + 2;
    merge.primitive.axis = {0, 0, 1};  // the strip's plane
  }
  return Hierarchy(mesh, {}, std::move(merges));
}

// log rms falling by `coarse` per level down to K = bend, then by `fine`: ratios of e^0.05 at most,
// far below a jump (2).
std::vector<double> bent_curve(std::uint32_t bend, double coarse, double fine, std::uint32_t size) {
  std::vector<double> rms(size);
  for (std::uint32_t k = 1; k <= size; ++k)
    rms[k - 1] =
        1000 * std::exp(-coarse * (std::min(k, bend) - 1.0) - fine * (k - std::min(k, bend)));
  return rms;
}

TEST(AutoLevel, ABendIsAKneeOnlyWhereTheCoarseLineIsMuchSteeper) {
  constexpr std::uint32_t kFaces = 1000;
  const Hierarchy sharp = hierarchy_with_curve(bent_curve(31, 0.05, 0.02, kFaces / 2), kFaces);
  const std::vector<ErrorCurvePoint> curve = error_curve(sharp);
  ASSERT_NEAR(curve[30].rms / curve[0].rms, std::exp(-1.5), 1e-12);  // the curve asked for
  const AutoLevel knee = choose_level(sharp);
  EXPECT_EQ(knee.rule, AutoLevelRule::Knee);
  EXPECT_GE(knee.clusters, 30u);  // K = 31 is on both lines
  EXPECT_LE(knee.clusters, 31u);
  // Steeper by 0.05 / 0.035 = 1.43 only, below min_score (2): the curve falls nearly evenly.
  const AutoLevel even =
      choose_level(hierarchy_with_curve(bent_curve(31, 0.05, 0.035, kFaces / 2), kFaces));
  EXPECT_EQ(even.rule, AutoLevelRule::Components);
  EXPECT_EQ(even.clusters, 1u);
}

// The L-method tries every split that leaves two points to each line, the first included: a
// curve whose only bend is after its first level (a fall of 1.9, short of a jump) bends there,
// and is not read as a later knee.
TEST(AutoLevel, TheBendAfterTheFirstLevelIsFoundAndTooSmall) {
  constexpr std::uint32_t kFaces = 1000;
  std::vector<double> rms = bent_curve(2, std::log(1.9), 0.06, kFaces / 2);
  const AutoLevel level = choose_level(hierarchy_with_curve(rms, kFaces));
  EXPECT_EQ(level.rule, AutoLevelRule::Components);
  EXPECT_EQ(level.clusters, 1u);
}

// A fine tessellation of a part whose clusters fit a little better as they shrink (as
// fandisk_large below): the curve falls steeply to its surfaces (K = 25), then gently on, and
// crosses the jumps' floor (1e-4 of the diagonal) at K = 1,205, within the knee's first range
// (F / 10 = 2,000). Floored there, it would be flat from 1,205 on, and that bend, the floor's own,
// is the one the L-method finds.
TEST(AutoLevel, ACurveGlidingIntoTheFloorKeepsTheKneeOfItsSurfaces) {
  constexpr std::uint32_t kFaces = 20000;
  const Hierarchy fine = hierarchy_with_curve(bent_curve(25, 0.165, 0.0025, kFaces / 2), kFaces);
  const double floor = 1e-4 * bounding_box_diagonal(fine.mesh());
  const std::vector<ErrorCurvePoint> curve = error_curve(fine);
  const auto onset = std::find_if(curve.begin(), curve.end(),
                                  [&](const ErrorCurvePoint& p) { return p.rms <= floor; });
  ASSERT_NE(onset, curve.end());
  EXPECT_GT(onset->clusters, 1000u);
  EXPECT_LT(onset->clusters, kFaces / 10);
  const AutoLevel level = choose_level(fine);
  EXPECT_EQ(level.rule, AutoLevelRule::Knee);
  EXPECT_GE(level.clusters, 24u);  // K = 25 is on both lines
  EXPECT_LE(level.clusters, 25u);
  // The knee floored as the jumps are: the floor's bend.
  AutoLevelOptions floored;
  floored.knee_rms_floor = floored.rms_floor;
  const AutoLevel at_the_floor = choose_level(fine, floored);
  EXPECT_EQ(at_the_floor.rule, AutoLevelRule::Knee);
  EXPECT_GT(at_the_floor.clusters, onset->clusters - 50);
  EXPECT_LE(at_the_floor.clusters, onset->clusters);
}

// The same on real meshes of libcgal-demo: fandisk_large (31,682 faces, its curve 10 times the
// floor at K = 25 and reaching it at 1,342) and rotor_small (4,800 faces, a coarse tessellation
// whose every facet is a plane: at 202 clusters, one a facet) get their surfaces, not the level
// where the curve meets the floor (they got 1,272 and 202 when the knee was floored at 1e-4).
TEST(AutoLevel, FineTessellationsGetTheKneeOfTheirSurfaces) {
  for (const auto& [name, lowest, highest] :
       {std::tuple{"fandisk_large.off", 20u, 30u}, std::tuple{"rotor_small.off", 10u, 15u}}) {
    const AutoLevel level = choose_level(build_hierarchy(read_mesh(testing::cgal_mesh(name))));
    EXPECT_EQ(level.rule, AutoLevelRule::Knee) << name;
    EXPECT_GE(level.clusters, lowest) << name;
    EXPECT_LE(level.clusters, highest) << name;
  }
}

TEST(AutoLevel, RulesHaveNames) {
  EXPECT_EQ(to_string(AutoLevelRule::Jump), "jump");
  EXPECT_EQ(to_string(AutoLevelRule::Knee), "knee");
  EXPECT_EQ(to_string(AutoLevelRule::Components), "components");
}

TEST(AutoLevel, CandidatesAreSortedAndBounded) {
  const GroundTruthShape shape = make_shape("box_with_blind_hole");
  AutoLevelOptions options;
  options.max_candidates = 3;
  const AutoLevel level = choose_level(build_hierarchy(shape.mesh), options);
  ASSERT_LE(level.candidates.size(), 4u);
  for (std::size_t i = 1; i < level.candidates.size(); ++i)
    EXPECT_GE(level.candidates[i - 1].score, level.candidates[i].score);
}

TEST(AutoLevel, RejectsUnusableOptions) {
  const Hierarchy h = build_hierarchy(make_shape("box").mesh);
  AutoLevelOptions bad;
  bad.rms_floor = -1;
  EXPECT_THROW(choose_level(h, bad), InvalidInputError);
  bad = {};
  bad.knee_rms_floor = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(choose_level(h, bad), InvalidInputError);
  bad = {};
  bad.min_score = 0.5;
  EXPECT_THROW(choose_level(h, bad), InvalidInputError);
  bad = {};
  bad.max_candidates = 0;
  EXPECT_THROW(choose_level(h, bad), InvalidInputError);
}

}  // namespace
}  // namespace primseg
