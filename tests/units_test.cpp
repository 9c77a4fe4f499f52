// Results do not depend on the units. Scaling a mesh by a power of two is exact in floating point,
// so every result must follow it exactly: the same tree, the same labels (refined borders
// included), the same skin weights, and every length of every primitive, denoised or posed
// position, bone and distance scaled by the same factor, bit for bit. An absolute constant
// anywhere in a computation (a step, a threshold, an epsilon) breaks this. Coordinates outside
// the range the geometry computes with are rejected with a message.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "primseg/bilateral_smoothing.hpp"
#include "primseg/cut.hpp"
#include "primseg/denoise.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_distance.hpp"
#include "primseg/refine.hpp"
#include "primseg/shape_generator.hpp"
#include "primseg/skeleton.hpp"
#include "primseg/skinning.hpp"

namespace primseg {
namespace {

Mesh scaled(Mesh mesh, double factor) {
  for (Vec3& p : mesh.positions)
    for (double& x : p) x *= factor;
  return mesh;
}

void expect_scaled(const Vec3& unit, const Vec3& scaled, double factor, const std::string& what) {
  for (int k = 0; k < 3; ++k) EXPECT_EQ(scaled[k], factor * unit[k]) << what << "[" << k << "]";
}

void expect_same_primitive(const Primitive& unit, const Primitive& scaled, double factor,
                           const std::string& what) {
  EXPECT_EQ(scaled.type, unit.type) << what;
  expect_scaled(unit.point, scaled.point, factor, what + " point");
  EXPECT_EQ(scaled.axis, unit.axis) << what << " axis";
  EXPECT_EQ(scaled.radius, factor * unit.radius) << what << " radius";
}

[[gnu::noinline]] DenoiseOptions bilateral_options() {
  DenoiseOptions options;
  options.bilateral_smoothing = BilateralSmoothingOptions{};
  return options;
}

// A noisy shape with planes and a concave cylinder, and the same without noise.
struct Shapes {
  Mesh noisy, clean;
  std::uint32_t regions = 0;
};

Shapes shapes() {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = 0.04;
  Shapes s;
  const GroundTruthShape clean = make_shape("box_with_hole", options);
  s.clean = clean.mesh;
  s.regions = static_cast<std::uint32_t>(clean.regions.size());
  options.noise = 0.003;
  options.seed = 11;
  s.noisy = make_shape("box_with_hole", options).mesh;
  return s;
}

class Units : public ::testing::TestWithParam<int> {};

TEST_P(Units, ScalingByAPowerOfTwoScalesEveryResultExactly) {
  const double factor = std::ldexp(1.0, GetParam());
  const Shapes unit = shapes();
  const Mesh noisy = scaled(unit.noisy, factor), clean = scaled(unit.clean, factor);

  // The tree: the same merges at the same (working-frame) costs.
  const Hierarchy unit_tree = build_hierarchy(unit.noisy, {});
  const Hierarchy tree = build_hierarchy(noisy, {});
  ASSERT_EQ(tree.merges().size(), unit_tree.merges().size());
  for (std::size_t i = 0; i < tree.merges().size(); ++i) {
    EXPECT_EQ(tree.merges()[i].first, unit_tree.merges()[i].first) << "merge " << i;
    EXPECT_EQ(tree.merges()[i].second, unit_tree.merges()[i].second) << "merge " << i;
    EXPECT_EQ(tree.merges()[i].cost, unit_tree.merges()[i].cost) << "merge " << i;
  }

  // Clusters and their fitted primitives (geometric refinement included).
  const Segmentation unit_level = cut_by_count(unit_tree, unit.regions);
  const Segmentation level = cut_by_count(tree, unit.regions);
  EXPECT_EQ(level.labels, unit_level.labels);
  const std::vector<ClusterReport> unit_reports = describe_clusters(unit_tree, unit_level);
  const std::vector<ClusterReport> reports = describe_clusters(tree, level);
  ASSERT_EQ(reports.size(), unit_reports.size());
  for (std::size_t c = 0; c < reports.size(); ++c) {
    const std::string what = "cluster " + std::to_string(c);
    expect_same_primitive(unit_reports[c].primitive, reports[c].primitive, factor, what);
    EXPECT_EQ(reports[c].rms, factor * unit_reports[c].rms) << what;
  }

  // Boundary refinement of a finer level.
  const RefinedLevel unit_refined = refine_boundaries(unit_tree, cut_by_count(unit_tree, 20));
  const RefinedLevel refined = refine_boundaries(tree, cut_by_count(tree, 20));
  EXPECT_GT(unit_refined.moved_faces, 0u);
  EXPECT_EQ(refined.segmentation.labels, unit_refined.segmentation.labels);
  ASSERT_EQ(refined.reports.size(), unit_refined.reports.size());
  for (std::size_t c = 0; c < refined.reports.size(); ++c)
    expect_same_primitive(unit_refined.reports[c].primitive, refined.reports[c].primitive, factor,
                          "refined cluster " + std::to_string(c));

  // Denoising, plain at the true level and bilateral at the automatic one.
  for (const bool bilateral : {false, true}) {
    SCOPED_TRACE(bilateral ? "bilateral, auto" : "plain, true level");
    const DenoiseOptions options = bilateral ? bilateral_options() : DenoiseOptions{};
    Denoiser unit_denoiser(unit.noisy, options), denoiser(noisy, options);
    if (bilateral) {
      const auto automatic = [](const Denoiser& d) {
        return [&d](const Hierarchy& h) { return d.automatic_level(h).segmentation; };
      };
      unit_denoiser.iterate(automatic(unit_denoiser));
      denoiser.iterate(automatic(denoiser));
    } else {
      unit_denoiser.iterate(level_by_count(unit.regions));
      denoiser.iterate(level_by_count(unit.regions));
    }
    std::uint32_t moved = 0;
    for (std::uint32_t v = 0; v < noisy.vertex_count(); ++v) {
      expect_scaled(unit_denoiser.mesh().positions[v], denoiser.mesh().positions[v], factor,
                    "vertex " + std::to_string(v));
      moved += denoiser.mesh().positions[v] != noisy.positions[v];
    }
    EXPECT_GT(moved, noisy.vertex_count() / 2);  // it did denoise
  }

  // Skeleton bones and joints.
  const Skeleton unit_skeleton = extract_skeleton(unit_tree, unit_level);
  const Skeleton skeleton = extract_skeleton(tree, level);
  ASSERT_EQ(skeleton.bones.size(), unit_skeleton.bones.size());
  for (std::size_t b = 0; b < skeleton.bones.size(); ++b) {
    const std::string what = "bone " + std::to_string(b);
    expect_scaled(unit_skeleton.bones[b].point, skeleton.bones[b].point, factor, what + " point");
    EXPECT_EQ(skeleton.bones[b].axis, unit_skeleton.bones[b].axis) << what;
  }
  ASSERT_EQ(skeleton.joints.size(), unit_skeleton.joints.size());
  for (std::size_t j = 0; j < skeleton.joints.size(); ++j)
    expect_scaled(unit_skeleton.joints[j].position, skeleton.joints[j].position, factor,
                  "joint " + std::to_string(j));
  // Skin weights are unitless; a pose moves the vertices by scaled amounts.
  const SkinWeights unit_weights = compute_skin_weights(unit.noisy, unit_skeleton);
  const SkinWeights weights = compute_skin_weights(noisy, skeleton);
  EXPECT_EQ(weights.bones, unit_weights.bones);
  EXPECT_EQ(weights.weights, unit_weights.weights);
  const std::vector<JointRotation> pose = {{0, {0, 0, 1}, 0.5}};
  const Mesh unit_posed = deform(unit.noisy, unit_skeleton, pose);
  const Mesh posed = deform(noisy, skeleton, pose);
  std::uint32_t posed_moved = 0;
  for (std::uint32_t v = 0; v < noisy.vertex_count(); ++v) {
    expect_scaled(unit_posed.positions[v], posed.positions[v], factor,
                  "posed vertex " + std::to_string(v));
    posed_moved += posed.positions[v] != noisy.positions[v];
  }
  EXPECT_GT(posed_moved, 0u);

  // Metro-style distances.
  DistanceOptions measure;
  measure.samples = 20000;
  const MeshDistance unit_distance = mesh_distance(unit.noisy, unit.clean, measure);
  const MeshDistance distance = mesh_distance(noisy, clean, measure);
  EXPECT_GT(unit_distance.rms, 0);
  EXPECT_EQ(distance.rms, factor * unit_distance.rms);
  EXPECT_EQ(distance.hausdorff, factor * unit_distance.hausdorff);
  EXPECT_EQ(distance.diagonal, factor * unit_distance.diagonal);
}

// 2^±100 (about 1e30 and 1e-30) are near both ends of the supported range.
INSTANTIATE_TEST_SUITE_P(PowersOfTwo, Units, ::testing::Values(-100, -20, 20, 100),
                         [](const ::testing::TestParamInfo<int>& param) {
                           return (param.param < 0 ? "Minus" : "Plus") +
                                  std::to_string(std::abs(param.param));
                         });

TEST(Units, CoordinatesOutsideTheSupportedRangeAreRejected) {
  const Mesh unit = shapes().clean;
  check_geometric_range(unit);
  check_geometric_range(scaled(unit, kMaxCoordinateMagnitude / 2));  // its coordinates are < 1
  check_geometric_range(scaled(unit, 0));                            // every face at one point
  auto expect_rejected = [](const Mesh& mesh, const std::string& words) {
    try {
      check_geometric_range(mesh);
      FAIL() << "accepted: " << words;
    } catch (const InvalidInputError& error) {
      EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
    }
    // Every operation that computes geometry checks it first.
    EXPECT_THROW(build_hierarchy(mesh, {}), InvalidInputError);
    EXPECT_THROW(Denoiser{mesh}, InvalidInputError);
    EXPECT_THROW(bilateral_smooth(mesh), InvalidInputError);
    EXPECT_THROW(mesh_distance(mesh, mesh), InvalidInputError);
  };
  Mesh far = unit;
  far.positions[3][1] = -1e40;
  expect_rejected(far, "vertex 3 has a coordinate of magnitude 1e+40, above the 1e+32");
  expect_rejected(scaled(unit, 1e-40), "below the 1e-32");
}

}  // namespace
}  // namespace primseg
