// JointRule::Limbs (skeleton.hpp): a limb attached to several clusters of a bulky body gets a
// sensitive joint where it is attached, while the paper's rule locks it into a hub. Checked on the
// generated stick figure with its ground-truth parts, its torso split in two.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "primseg/error.hpp"
#include "primseg/skeleton.hpp"
#include "primseg/skinning.hpp"
#include "support/stick_figure.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using testing::distance;
using testing::make_stick_figure;
using testing::StickFigure;

const StickFigure& figure() {
  static const StickFigure instance = make_stick_figure();
  return instance;
}

// The ground-truth parts as labels, the torso (label 0, the root bone) cut by the plane y = 0
// into a front (0) and a back (a label after the other parts): every shoulder and hip boundary
// then meets both halves, which meet each other there.
std::vector<std::uint32_t> split_torso_labels(const StickFigure& f) {
  const auto back = static_cast<std::uint32_t>(f.parts.size());
  std::vector<std::uint32_t> labels = f.part_of_face;
  for (std::uint32_t face = 0; face < f.mesh.face_count(); ++face) {
    if (labels[face] != f.part("torso")) continue;
    double y = 0;
    for (const std::uint32_t v : f.mesh.triangles[face]) y += f.mesh.positions[v][1];
    if (y < 0) labels[face] = back;
  }
  return labels;
}

Skeleton split_figure_skeleton(JointRule rule) {
  const StickFigure& f = figure();
  SkeletonOptions options;
  options.joints = rule;
  return extract_skeleton(f.mesh, split_torso_labels(f), std::vector<Primitive>(f.parts.size() + 1),
                          options);
}

// The joints of `bone` that also have one of `others`.
std::vector<std::uint32_t> joints_with(const Skeleton& skeleton, std::uint32_t bone,
                                       const std::set<std::uint32_t>& others) {
  std::vector<std::uint32_t> result;
  for (const std::uint32_t j : skeleton.bones[bone].joints)
    for (const std::uint32_t b : skeleton.joints[j].bones)
      if (others.contains(b)) {
        result.push_back(j);
        break;
      }
  return result;
}

const char* const kAttachedLimbs[] = {"upper_arm_left", "upper_arm_right", "leg_left", "leg_right"};

TEST(LimbJoints, ThePapersRuleLocksALimbThatMeetsTwoClustersOfTheBody) {
  const StickFigure& f = figure();
  const Skeleton skeleton = split_figure_skeleton(JointRule::Paper);
  const std::set<std::uint32_t> halves{f.part("torso"), static_cast<std::uint32_t>(f.parts.size())};
  for (const char* limb : kAttachedLimbs) {
    const std::vector<std::uint32_t> attachment = joints_with(skeleton, f.part(limb), halves);
    ASSERT_EQ(attachment.size(), 1u) << limb;
    EXPECT_EQ(skeleton.joints[attachment[0]].kind, JointKind::Locked) << limb;
  }
}

TEST(LimbJoints, ALimbTurnsWhereItIsAttached) {
  const StickFigure& f = figure();
  const Skeleton skeleton = split_figure_skeleton(JointRule::Limbs);
  const std::set<std::uint32_t> halves{f.part("torso"), static_cast<std::uint32_t>(f.parts.size())};
  for (const char* limb : kAttachedLimbs) {
    const std::uint32_t bone = f.part(limb);
    const std::vector<std::uint32_t> attachment = joints_with(skeleton, bone, halves);
    ASSERT_EQ(attachment.size(), 1u) << limb;
    const Joint& joint = skeleton.joints[attachment[0]];
    EXPECT_EQ(joint.kind, JointKind::Sensitive) << limb;
    ASSERT_EQ(joint.bones.size(), 2u) << limb;
    EXPECT_TRUE(std::find(joint.bones.begin(), joint.bones.end(), bone) != joint.bones.end());
    // At the centroid of the whole attachment curve, as where the torso is one cluster: the
    // limb's axis just inside the torso's surface.
    const double radius = std::string(limb).starts_with("leg") ? f.leg_radius : f.arm_radius;
    EXPECT_LT(distance(joint.position, f.attachment[bone]), 0.25 * radius) << limb;
    // Turning it carries the limb and what hangs from it, nothing else.
    std::vector<std::uint32_t> carried{bone};
    if (std::string(limb).starts_with("upper_arm"))
      carried.push_back(f.part("forearm" + std::string(limb).substr(9)));
    std::sort(carried.begin(), carried.end());
    EXPECT_EQ(bones_beyond(skeleton, joint.id), carried) << limb;
  }
  // The two halves the limbs hang from stay rigid together: their own boundary is locked.
  const std::vector<std::uint32_t> between =
      joints_with(skeleton, f.part("torso"), {static_cast<std::uint32_t>(f.parts.size())});
  ASSERT_FALSE(between.empty());
  for (const std::uint32_t j : between) EXPECT_EQ(skeleton.joints[j].kind, JointKind::Locked);
}

TEST(LimbJoints, TurningAHipMovesTheLegRigidlyAndNothingElse) {
  const StickFigure& f = figure();
  const Skeleton skeleton = split_figure_skeleton(JointRule::Limbs);
  const std::uint32_t leg = f.part("leg_right");
  const std::vector<std::uint32_t> hip =
      joints_with(skeleton, leg, {f.part("torso"), static_cast<std::uint32_t>(f.parts.size())});
  ASSERT_EQ(hip.size(), 1u);
  const JointRotation rotation{hip[0], {1, 0, 0}, 0.8};
  const SkinWeights weights = compute_skin_weights(f.mesh, skeleton);
  const std::vector<Vec3> posed =
      skin_positions(f.mesh.positions, weights, pose_bones(skeleton, {&rotation, 1}));
  std::vector<std::uint32_t> rigid;  // leg vertices of weight 1 to the leg
  for (std::uint32_t v = 0; v < f.mesh.vertex_count(); ++v) {
    const auto bones = weights.bones_of(v);
    if (bones.size() == 1 && bones[0] == leg) rigid.push_back(v);
    if (std::find(bones.begin(), bones.end(), leg) == bones.end()) {
      ASSERT_EQ(posed[v], f.mesh.positions[v]) << "vertex " << v << " moved";
    }
  }
  ASSERT_GT(rigid.size(), 50u);
  double worst = 0, farthest = 0;
  for (std::size_t i = 0; i < rigid.size(); ++i) {
    farthest = std::max(farthest, distance(posed[rigid[i]], f.mesh.positions[rigid[i]]));
    for (std::size_t j = i + 1; j < rigid.size(); j += 7) {
      const double before = distance(f.mesh.positions[rigid[i]], f.mesh.positions[rigid[j]]);
      const double after = distance(posed[rigid[i]], posed[rigid[j]]);
      worst = std::max(worst, std::abs(after - before) / before);
    }
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(farthest, 0.5 * f.leg_radius) << "the leg did not move";
}

// Where the paper's rule already frees every limb (the figure's torso one cluster), the limb rule
// gives the same skeleton.
TEST(LimbJoints, AgreeWithThePapersRuleWhereItFreesEveryLimb) {
  const StickFigure& f = figure();
  const std::vector<Primitive> primitives(f.parts.size());
  SkeletonOptions limbs;
  limbs.joints = JointRule::Limbs;
  const Skeleton paper = extract_skeleton(f.mesh, f.part_of_face, primitives);
  const Skeleton with_limbs = extract_skeleton(f.mesh, f.part_of_face, primitives, limbs);
  ASSERT_EQ(paper.joints.size(), with_limbs.joints.size());
  for (std::size_t j = 0; j < paper.joints.size(); ++j) {
    EXPECT_EQ(paper.joints[j].position, with_limbs.joints[j].position) << j;
    EXPECT_EQ(paper.joints[j].bones, with_limbs.joints[j].bones) << j;
    EXPECT_EQ(paper.joints[j].kind, with_limbs.joints[j].kind) << j;
  }
}

// A tube closed on itself (a torus) in three sectors, the first split into a top (0) and a
// bottom (3) half. Sectors 1 and 2 reach far beyond their loops, but each loop of one leads, round
// the ring, to the other's: cutting one frees nothing, so neither is a limb, and where each meets
// the split sector stays in a locked hub, as by the paper's rule.
TEST(LimbJoints, ALoopThatDoesNotSeparateTheSurfaceIsNoLimb) {
  const std::uint32_t around = 36, across = 12;  // about the axis, about the tube
  std::vector<Vec3> positions;
  for (std::uint32_t i = 0; i < around; ++i)
    for (std::uint32_t j = 0; j < across; ++j) {
      const double a = 2 * std::numbers::pi * i / around, b = 2 * std::numbers::pi * j / across;
      positions.push_back(
          {(3 + std::cos(b)) * std::cos(a), (3 + std::cos(b)) * std::sin(a), std::sin(b)});
    }
  const auto id = [&](std::uint32_t i, std::uint32_t j) {
    return (i % around) * across + j % across;
  };
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> labels;
  for (std::uint32_t i = 0; i < around; ++i)
    for (std::uint32_t j = 0; j < across; ++j) {
      triangles.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
      triangles.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      const std::uint32_t sector = 3 * i / around;
      const std::uint32_t label = sector == 0 && 2 * j >= across ? 3 : sector;  // z < 0: 3
      labels.insert(labels.end(), 2, label);
    }
  const Mesh torus = Mesh::from_triangles(std::move(positions), std::move(triangles));
  SkeletonOptions limbs;
  limbs.joints = JointRule::Limbs;
  const std::vector<Primitive> primitives(4);
  for (const Skeleton& skeleton : {extract_skeleton(torus, labels, primitives),
                                   extract_skeleton(torus, labels, primitives, limbs)})
    for (const std::uint32_t sector : {1u, 2u}) {
      const std::vector<std::uint32_t> attached = joints_with(skeleton, sector, {0u, 3u});
      ASSERT_EQ(attached.size(), 1u) << sector;
      EXPECT_EQ(skeleton.joints[attached[0]].kind, JointKind::Locked) << sector;
      // (The halves' boundary runs from sector 1 to sector 2: one hub of all four.)
      EXPECT_EQ(skeleton.joints[attached[0]].bones.size(), 4u) << sector;
    }
}

TEST(LimbJoints, ABadProtrusionIsRejected) {
  const StickFigure& f = figure();
  const std::vector<Primitive> primitives(f.parts.size());
  for (const double bad : {-1.0, std::nan(""), double{INFINITY}}) {
    SkeletonOptions options;
    options.joints = JointRule::Limbs;
    options.limb_protrusion = bad;
    EXPECT_THROW(extract_skeleton(f.mesh, f.part_of_face, primitives, options), InvalidInputError)
        << bad;
  }
  EXPECT_EQ(joint_rule_from_string("limbs"), JointRule::Limbs);
  EXPECT_EQ(joint_rule_from_string("paper"), JointRule::Paper);
  EXPECT_EQ(joint_rule_from_string("hubs"), std::nullopt);
}

}  // namespace
}  // namespace primseg
