// Skeleton extraction and skinning on a generated stick figure (tests/support/stick_figure.hpp)
// and on small meshes whose answer is known by construction.

#include "primseg/skeleton.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/skeleton_gltf.hpp"
#include "primseg/skeleton_render.hpp"
#include "primseg/skinning.hpp"
#include "support/stick_figure.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using testing::make_stick_figure;
using testing::StickFigure;

using testing::distance;

double triangle_area(const Mesh& mesh, const Triangle& t) {
  const Vec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return 0.5 * std::hypot(u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                          u[0] * v[1] - u[1] * v[0]);
}

HierarchyOptions with_primitives(std::vector<PrimitiveType> types) {
  HierarchyOptions options;
  options.primitives = std::move(types);
  return options;
}

// The figure, its hierarchy cut at K clusters, and the skeleton. By default: cylinders for the
// limbs and torso, spheres for the head, cut at the number of parts.
struct FigureSkeleton {
  StickFigure figure = make_stick_figure();
  Hierarchy hierarchy;
  Segmentation level;
  Skeleton skeleton;
  // Bone of each ground-truth part: the cluster overlapping it most (by area).
  std::vector<std::uint32_t> bone_of_part;
  std::vector<double> iou_of_part;

  explicit FigureSkeleton(std::vector<PrimitiveType> types = {PrimitiveType::Cylinder,
                                                              PrimitiveType::Sphere},
                          std::uint32_t clusters = 8)
      : hierarchy(build_hierarchy(figure.mesh, with_primitives(std::move(types)))),
        level(cut_by_count(hierarchy, clusters)),
        skeleton(extract_skeleton(hierarchy, level)) {
    const std::size_t parts = figure.parts.size(), k = level.cluster_count();
    std::vector<std::vector<double>> overlap(parts, std::vector<double>(k, 0));
    std::vector<double> part_area(parts, 0), cluster_area(k, 0);
    for (std::uint32_t f = 0; f < figure.mesh.face_count(); ++f) {
      const double area = triangle_area(figure.mesh, figure.mesh.triangles[f]);
      overlap[figure.part_of_face[f]][level.labels[f]] += area;
      part_area[figure.part_of_face[f]] += area;
      cluster_area[level.labels[f]] += area;
    }
    for (std::size_t p = 0; p < parts; ++p) {
      const auto best = std::max_element(overlap[p].begin(), overlap[p].end()) - overlap[p].begin();
      bone_of_part.push_back(static_cast<std::uint32_t>(best));
      iou_of_part.push_back(overlap[p][best] /
                            (part_area[p] + cluster_area[best] - overlap[p][best]));
    }
  }

  std::uint32_t bone(const std::string& part) const { return bone_of_part[figure.part(part)]; }
  // The joint shared by two bones (the test fails when there is none).
  std::uint32_t joint_between(std::uint32_t a, std::uint32_t b) const {
    for (const std::uint32_t j : skeleton.bones[a].joints) {
      const auto& bones = skeleton.joints[j].bones;
      if (std::find(bones.begin(), bones.end(), b) != bones.end()) return j;
    }
    ADD_FAILURE() << "bones " << a << " and " << b << " share no joint";
    return 0;
  }
};

const FigureSkeleton& figure_skeleton() {
  static const FigureSkeleton instance;
  return instance;
}

const char* const kLimbs[] = {"upper_arm_left", "upper_arm_right", "forearm_left",
                              "forearm_right",  "leg_left",        "leg_right"};

// The part a limb hangs from.
std::string parent_part(const std::string& limb) {
  return limb.starts_with("forearm") ? "upper_arm" + limb.substr(7) : "torso";
}

TEST(StickFigure, IsAConformingMeshWithEveryVertexOnItsPart) {
  const StickFigure figure = make_stick_figure();
  EXPECT_NO_THROW(figure.mesh.validate());
  EXPECT_EQ(figure.part_of_face.size(), figure.mesh.face_count());
  // Limb vertices lie on their cylinder (axis through the attachment point).
  for (const char* name : {"upper_arm_right", "leg_left"}) {
    const std::uint32_t part = figure.part(name);
    const double radius =
        std::string(name).starts_with("leg") ? figure.leg_radius : figure.arm_radius;
    for (std::uint32_t f = 0; f < figure.mesh.face_count(); ++f) {
      if (figure.part_of_face[f] != part) continue;
      for (const std::uint32_t v : figure.mesh.triangles[f]) {
        const Vec3& x = figure.mesh.positions[v];
        const Vec3& p = figure.attachment[part];
        const Vec3& a = figure.axis[part];
        const Vec3 d{x[0] - p[0], x[1] - p[1], x[2] - p[2]};
        const double along = d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
        const double off =
            std::sqrt(std::max(0.0, d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - along * along));
        ASSERT_NEAR(off, radius, 1e-12) << name;
      }
    }
  }
}

// Cylinders only (the command's default): a sphere is no cylinder, so the head splits into
// several bones (4 here), but every limb segment and the torso are still a bone each at K = 12.
TEST(Skeleton, CylinderOnlyHierarchyKeepsEveryLimbSegmentOneBone) {
  const FigureSkeleton s({PrimitiveType::Cylinder}, 12);
  ASSERT_EQ(s.skeleton.cluster_count(), 12u);
  std::set<std::uint32_t> distinct;
  for (const char* part : kLimbs) {
    EXPECT_GE(s.iou_of_part[s.figure.part(part)], 0.95) << part;
    distinct.insert(s.bone(part));
  }
  EXPECT_GE(s.iou_of_part[s.figure.part("torso")], 0.95);
  distinct.insert(s.bone("torso"));
  EXPECT_EQ(distinct.size(), 7u);
  for (const char* limb : kLimbs) {
    const Bone& bone = s.skeleton.bones[s.bone(limb)];
    EXPECT_EQ(bone.joints.size(), 2u) << limb;
    EXPECT_EQ(s.skeleton.joints[s.joint_between(bone.id, s.bone(parent_part(limb)))].kind,
              JointKind::Sensitive)
        << limb;
  }
}

TEST(Skeleton, FindsOneBonePerPartAtTheRightK) {
  const FigureSkeleton& s = figure_skeleton();
  ASSERT_EQ(s.skeleton.cluster_count(), s.figure.parts.size());
  std::set<std::uint32_t> distinct(s.bone_of_part.begin(), s.bone_of_part.end());
  EXPECT_EQ(distinct.size(), s.figure.parts.size()) << "two parts share a bone";
  for (std::size_t p = 0; p < s.figure.parts.size(); ++p)
    EXPECT_GE(s.iou_of_part[p], 0.95) << s.figure.parts[p];
  EXPECT_EQ(s.skeleton.root_bone(), s.bone("torso"));

  // Torso: a joint with each limb attached to it and with the head, all sensitive.
  const Bone& torso = s.skeleton.bones[s.bone("torso")];
  EXPECT_EQ(torso.joints.size(), 5u);
  EXPECT_TRUE(torso.visible);
  for (const std::uint32_t j : torso.joints) {
    EXPECT_EQ(s.skeleton.joints[j].kind, JointKind::Sensitive);
    EXPECT_EQ(s.skeleton.joints[j].bones.size(), 2u);
  }
  // Limb segments: two joints each; the free ends are virtual.
  for (const char* limb : kLimbs) {
    const Bone& bone = s.skeleton.bones[s.bone(limb)];
    ASSERT_EQ(bone.joints.size(), 2u) << limb;
    std::multiset<JointKind> kinds;
    for (const std::uint32_t j : bone.joints) kinds.insert(s.skeleton.joints[j].kind);
    const bool upper_arm = std::string(limb).starts_with("upper");
    EXPECT_EQ(kinds.count(JointKind::Sensitive), upper_arm ? 2u : 1u) << limb;
    EXPECT_EQ(kinds.count(JointKind::Virtual), upper_arm ? 0u : 1u) << limb;
    EXPECT_TRUE(bone.visible);
    // The bone follows its limb: the fitted cylinder's axis and radius.
    const Vec3& truth = s.figure.axis[s.figure.part(limb)];
    const double cosine =
        std::abs(bone.axis[0] * truth[0] + bone.axis[1] * truth[1] + bone.axis[2] * truth[2]);
    EXPECT_GT(cosine, 1 - 1e-6) << limb;
  }
  for (const Joint& joint : s.skeleton.joints) EXPECT_TRUE(joint.visible);
}

TEST(Skeleton, ShoulderAndHipJointsAreWhereTheLimbsMeetTheTorso) {
  const FigureSkeleton& s = figure_skeleton();
  for (const char* limb : {"upper_arm_left", "upper_arm_right", "leg_left", "leg_right"}) {
    const std::uint32_t joint = s.joint_between(s.bone("torso"), s.bone(limb));
    const double radius =
        std::string(limb).starts_with("leg") ? s.figure.leg_radius : s.figure.arm_radius;
    const double off =
        distance(s.skeleton.joints[joint].position, s.figure.attachment[s.figure.part(limb)]);
    RecordProperty(std::string(limb) + "_joint_offset", std::to_string(off));
    // The centroid of the intersection curve lies on the limb's axis, just inside the torso's
    // surface (the curve dips around the torso).
    EXPECT_LT(off, 0.25 * radius) << limb;
  }
  // An elbow's boundary is the mitre ellipse, centrally symmetric about the elbow centre.
  for (int side = 0; side < 2; ++side) {
    const char* upper = side == 0 ? "upper_arm_left" : "upper_arm_right";
    const char* fore = side == 0 ? "forearm_left" : "forearm_right";
    const std::uint32_t joint = s.joint_between(s.bone(upper), s.bone(fore));
    EXPECT_LT(distance(s.skeleton.joints[joint].position, s.figure.elbow[side]), 1e-9);
  }
}

TEST(Skinning, WeightsAreAPartitionOfUnityBlendedOnlyNearJoints) {
  const FigureSkeleton& s = figure_skeleton();
  const SkinWeights weights = compute_skin_weights(s.figure.mesh, s.skeleton);
  ASSERT_EQ(weights.vertex_count(), s.figure.mesh.vertex_count());
  std::size_t blended = 0;
  for (std::uint32_t v = 0; v < weights.vertex_count(); ++v) {
    double sum = 0;
    for (const double w : weights.weights_of(v)) {
      EXPECT_GT(w, 0);
      EXPECT_LE(w, 1);
      sum += w;
    }
    EXPECT_NEAR(sum, 1, 1e-12);
    blended += weights.bones_of(v).size() > 1;
  }
  // Inside a cluster each neighbour's weight, (1 − s(d / band)) / 2, is below 1/2 off the
  // boundary, and the own bone's is the largest (below 1/2 only near several boundaries).
  std::vector<std::set<std::uint32_t>> clusters_of(s.figure.mesh.vertex_count());
  for (std::uint32_t f = 0; f < s.figure.mesh.face_count(); ++f)
    for (const std::uint32_t v : s.figure.mesh.triangles[f])
      clusters_of[v].insert(s.skeleton.face_labels[f]);
  for (std::uint32_t v = 0; v < weights.vertex_count(); ++v) {
    if (clusters_of[v].size() != 1) continue;
    const std::uint32_t own = *clusters_of[v].begin();
    const auto bones = weights.bones_of(v);
    const auto w = weights.weights_of(v);
    const std::size_t largest = std::max_element(w.begin(), w.end()) - w.begin();
    EXPECT_EQ(bones[largest], own) << "vertex " << v;
    for (std::size_t i = 0; i < bones.size(); ++i) {
      if (bones[i] != own) {
        EXPECT_LT(w[i], 0.5) << "vertex " << v;
      }
    }
  }
  // Only a band near each of the 7 joints blends: a minority of the vertices.
  EXPECT_GT(blended, 0u);
  EXPECT_LT(blended, weights.vertex_count() / 2);
  // Vertices on the elbow's boundary are half and half.
  const std::uint32_t upper = s.bone("upper_arm_right"), fore = s.bone("forearm_right");
  std::size_t boundary = 0;
  for (std::uint32_t f = 0; f < s.figure.mesh.face_count(); ++f) {
    if (s.skeleton.face_labels[f] != fore) continue;
    for (const std::uint32_t v : s.figure.mesh.triangles[f]) {
      const auto bones = weights.bones_of(v);
      if (std::find(bones.begin(), bones.end(), upper) == bones.end()) continue;
      // On the mitre plane (the boundary)?
      if (distance(s.figure.mesh.positions[v], s.figure.elbow[1]) > s.figure.arm_radius * 1.5)
        continue;
      const auto w = weights.weights_of(v);
      if (std::abs(w[0] - w[1]) < 1e-12) ++boundary;
    }
  }
  EXPECT_GT(boundary, 0u);
}

TEST(Skinning, WideBandsOverlappingAtShortBonesStillPartitionUnity) {
  // A band of 10 bone radii reaches across whole limb segments, so vertices sit in the bands of
  // several boundaries at once: the neighbours' shares are scaled down, never the own one below 0.
  const FigureSkeleton& s = figure_skeleton();
  SkinningOptions options;
  options.band = 10;
  const SkinWeights weights = compute_skin_weights(s.figure.mesh, s.skeleton, options);
  std::size_t three_or_more = 0;
  for (std::uint32_t v = 0; v < weights.vertex_count(); ++v) {
    double sum = 0;
    for (const double w : weights.weights_of(v)) {
      EXPECT_GT(w, 0) << "vertex " << v;
      EXPECT_LE(w, 1) << "vertex " << v;
      sum += w;
    }
    EXPECT_NEAR(sum, 1, 1e-12) << "vertex " << v;
    three_or_more += weights.bones_of(v).size() >= 3;
  }
  EXPECT_GT(three_or_more, 0u);
}

// Rotating the right elbow by 90 degrees about the normal of the arm's plane.
TEST(Skinning, ElbowRotationMovesTheForearmRigidlyAndLeavesTheTorsoStill) {
  const FigureSkeleton& s = figure_skeleton();
  const Mesh& mesh = s.figure.mesh;
  const std::uint32_t upper = s.bone("upper_arm_right"), fore = s.bone("forearm_right");
  const std::uint32_t elbow = s.joint_between(upper, fore);
  EXPECT_EQ(bones_beyond(s.skeleton, elbow), std::vector<std::uint32_t>{fore});

  const JointRotation rotation{elbow, {0, 1, 0}, std::numbers::pi / 2};
  const SkinWeights weights = compute_skin_weights(mesh, s.skeleton);
  const std::vector<RigidTransform> bones = pose_bones(s.skeleton, {&rotation, 1});
  const std::vector<Vec3> posed = skin_positions(mesh.positions, weights, bones);

  // Forearm vertices outside the blend band (weight 1 to the forearm).
  std::vector<std::uint32_t> rigid;
  std::set<std::uint32_t> forearm_vertices;
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f)
    if (s.skeleton.face_labels[f] == fore)
      forearm_vertices.insert(mesh.triangles[f].begin(), mesh.triangles[f].end());
  for (const std::uint32_t v : forearm_vertices)
    if (weights.bones_of(v).size() == 1 && weights.bones_of(v)[0] == fore) rigid.push_back(v);
  ASSERT_GT(rigid.size(), forearm_vertices.size() / 2);
  double worst = 0, largest_move = 0;
  for (std::size_t i = 0; i < rigid.size(); ++i) {
    largest_move = std::max(largest_move, distance(posed[rigid[i]], mesh.positions[rigid[i]]));
    for (std::size_t j = i + 1; j < rigid.size(); ++j) {
      const double before = distance(mesh.positions[rigid[i]], mesh.positions[rigid[j]]);
      const double after = distance(posed[rigid[i]], posed[rigid[j]]);
      worst = std::max(worst, std::abs(after - before) / before);
    }
  }
  std::ostringstream measured;
  measured << worst;
  RecordProperty("forearm_distance_relative_error", measured.str());
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(largest_move, 0.5) << "the forearm did not move";
  // The forearm's free end turned by 90 degrees about the elbow.
  const Bone& forearm = s.skeleton.bones[fore];
  for (const std::uint32_t j : forearm.joints) {
    if (s.skeleton.joints[j].kind != JointKind::Virtual) continue;
    const Vec3 p = s.skeleton.joints[j].position;
    const Vec3 c = s.figure.elbow[1];
    const Vec3 moved = posed_joint_positions(s.skeleton, bones)[j];
    // About +y by 90 degrees: (x, z) offsets -> (z, -x).
    EXPECT_NEAR(moved[0] - c[0], p[2] - c[2], 1e-9);
    EXPECT_NEAR(moved[2] - c[2], -(p[0] - c[0]), 1e-9);
    EXPECT_NEAR(moved[1], p[1], 1e-9);
  }
  // Every vertex with no weight on the forearm stays exactly where it was: the torso, the head,
  // the legs, the other arm and the upper arm itself.
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    const auto b = weights.bones_of(v);
    if (std::find(b.begin(), b.end(), fore) != b.end()) continue;
    ASSERT_EQ(posed[v], mesh.positions[v]) << "vertex " << v;
  }
}

TEST(Skinning, ShoulderRotationCarriesTheWholeArm) {
  const FigureSkeleton& s = figure_skeleton();
  const std::uint32_t upper = s.bone("upper_arm_left"), fore = s.bone("forearm_left");
  const std::uint32_t shoulder = s.joint_between(s.bone("torso"), upper);
  const std::uint32_t elbow = s.joint_between(upper, fore);
  EXPECT_EQ(bones_beyond(s.skeleton, shoulder),
            (std::vector<std::uint32_t>{std::min(upper, fore), std::max(upper, fore)}));
  // Shoulder then elbow: the forearm's transform is the composition.
  const JointRotation pose[] = {{shoulder, {0, 0, 1}, 0.7}, {elbow, {0, 1, 0}, -0.4}};
  const auto bones = pose_bones(s.skeleton, pose);
  const RigidTransform expected =
      RigidTransform::rotation_about(s.skeleton.joints[shoulder].position, {0, 0, 1}, 0.7) *
      RigidTransform::rotation_about(s.skeleton.joints[elbow].position, {0, 1, 0}, -0.4);
  const Vec3 x{-3, 0.2, 2.5};
  const Vec3 got = bones[fore].apply(x), want = expected.apply(x);
  EXPECT_LT(distance(got, want), 1e-12);
  EXPECT_EQ(bones[s.bone("torso")].apply(x), x);
}

// An axis of any finite, non-zero length: before, one whose norm overflowed (1e308) or underflowed
// (subnormal components) was rejected as not finite or zero.
TEST(Skinning, AnAxisOfAnyLengthGivesTheSameRotation) {
  const FigureSkeleton& s = figure_skeleton();
  const std::uint32_t shoulder = s.joint_between(s.bone("torso"), s.bone("upper_arm_left"));
  const std::uint32_t upper = s.bone("upper_arm_left");
  const auto transform = [&](Vec3 axis) {
    const JointRotation rotation{shoulder, axis, 0.7};
    return pose_bones(s.skeleton, {&rotation, 1})[upper];
  };
  const Vec3 x{-3, 0.2, 2.5};
  const Vec3 reference = transform({1, 1, 0}).apply(x);
  EXPECT_EQ(transform({1e308, 1e308, 0}).apply(x), reference);
  EXPECT_EQ(transform({4e-320, 4e-320, 0}).apply(x), reference);
  EXPECT_EQ(transform({2, 2, 0}).apply(x), reference);
}

TEST(Skinning, PosesThatCannotBeAppliedAreRejected) {
  const FigureSkeleton& s = figure_skeleton();
  std::uint32_t virtual_joint = 0;
  for (const Joint& joint : s.skeleton.joints)
    if (joint.kind == JointKind::Virtual) virtual_joint = joint.id;
  const std::uint32_t shoulder = s.joint_between(s.bone("torso"), s.bone("upper_arm_left"));
  const auto rejects = [&](JointRotation rotation) {
    return [&s, rotation] { pose_bones(s.skeleton, {&rotation, 1}); };
  };
  EXPECT_THROW(rejects({virtual_joint, {0, 0, 1}, 1})(), InvalidInputError);
  EXPECT_THROW(rejects({9999, {0, 0, 1}, 1})(), InvalidInputError);
  EXPECT_THROW(rejects({shoulder, {0, 0, 0}, 1})(), InvalidInputError);
  EXPECT_THROW(rejects({shoulder, {0, 0, 1}, NAN})(), InvalidInputError);
  EXPECT_THROW(rejects({shoulder, {0, INFINITY, 1}, 1})(), InvalidInputError);
  const JointRotation twice[] = {{shoulder, {0, 0, 1}, 1}, {shoulder, {0, 1, 0}, 1}};
  EXPECT_THROW(pose_bones(s.skeleton, twice), InvalidInputError);
  SkinningOptions bad;
  bad.band = -1;
  EXPECT_THROW(compute_skin_weights(s.figure.mesh, s.skeleton, bad), InvalidInputError);
  Mesh unknown_vertex = s.figure.mesh;
  unknown_vertex.triangles[7][2] = static_cast<std::uint32_t>(unknown_vertex.vertex_count());
  EXPECT_THROW(compute_skin_weights(unknown_vertex, s.skeleton), InvalidInputError);
}

TEST(Skinning, SkinningChecksItsSizesAndLeavesUnweightedVerticesAtRest) {
  // Vertex 0 follows bone 1 alone, vertex 1 (used by no triangle) has no bone, vertex 2 is
  // halfway between bones 0 and 1.
  SkinWeights weights;
  weights.offsets = {0, 1, 1, 3};
  weights.bones = {1, 0, 1};
  weights.weights = {1.0, 0.5, 0.5};
  const std::vector<Vec3> rest{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  RigidTransform shift;
  shift.translation = {0, 0, 2};
  const std::vector<RigidTransform> transforms{RigidTransform{}, shift};
  const std::vector<Vec3> posed = skin_positions(rest, weights, transforms);
  EXPECT_EQ(posed[0], (Vec3{1, 0, 2}));
  EXPECT_EQ(posed[1], rest[1]);
  EXPECT_EQ(posed[2], (Vec3{0, 0, 2}));

  EXPECT_THROW(skin_positions({rest.data(), 2}, weights, transforms), InvalidInputError);
  EXPECT_THROW(skin_positions(rest, weights, {transforms.data(), 1}), InvalidInputError);
}

// A book of pages on one spine edge, a cluster per page: consecutive pages (by triangle, as the
// dual graph links them) meet along the spine, and those boundaries all touch: one locked joint
// of every bone at the spine's midpoint, and no free end. Every pair of pages meeting would be
// N(N − 1)/2 boundaries.
TEST(Skeleton, ABookIsOneJointOnItsSpine) {
  constexpr std::uint32_t kPages = 3000;
  std::vector<std::uint32_t> labels(kPages);
  for (std::uint32_t i = 0; i < kPages; ++i) labels[i] = i;
  const Skeleton skeleton =
      extract_skeleton(testing::book(kPages), labels, std::vector<Primitive>(kPages));
  ASSERT_EQ(skeleton.joints.size(), 1u);
  const Joint& spine = skeleton.joints[0];
  EXPECT_EQ(spine.kind, JointKind::Locked);
  EXPECT_EQ(spine.bones.size(), kPages);
  EXPECT_NEAR(spine.position[0], 0, 1e-12);
  EXPECT_NEAR(spine.position[1], 0, 1e-12);
  EXPECT_NEAR(spine.position[2], 0.5, 1e-12);
}

// Three clusters of a square meeting at its centre: their boundaries touch there, so they share
// one locked joint; no bone keeps a movable joint, so all are hidden, and so is the joint.
TEST(Skeleton, TouchingBoundariesMergeIntoOneLockedJoint) {
  const Mesh mesh = testing::grid_mesh(8, 8, [](double u, double v) { return Vec3{u, v, 0}; });
  std::vector<std::uint32_t> labels(mesh.face_count());
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f) {
    Vec3 c{0, 0, 0};
    for (const std::uint32_t v : mesh.triangles[f])
      for (int i = 0; i < 3; ++i) c[i] += mesh.positions[v][i] / 3;
    labels[f] = c[0] < 0.5 ? 0 : (c[1] < 0.5 ? 1 : 2);
  }
  const std::vector<Primitive> planes(3);
  const Skeleton skeleton = extract_skeleton(mesh, labels, planes);
  ASSERT_EQ(skeleton.joints.size(), 1u);
  const Joint& joint = skeleton.joints[0];
  EXPECT_EQ(joint.kind, JointKind::Locked);
  EXPECT_EQ(joint.bones, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_FALSE(joint.visible);
  for (const Bone& bone : skeleton.bones) {
    EXPECT_EQ(bone.joints, std::vector<std::uint32_t>{0});
    EXPECT_FALSE(bone.visible);
  }
  // The joint is the length-weighted centroid of the three boundaries: (0.5, 0.5) and the
  // half-segment (0.5..1, 0.5), weights 1 and 0.5.
  EXPECT_NEAR(joint.position[0], (0.5 * 1 + 0.75 * 0.5) / 1.5, 1e-12);
  EXPECT_NEAR(joint.position[1], 0.5, 1e-12);

  // Two halves: one sensitive joint on the dividing line, a virtual joint at each far end.
  for (std::uint32_t& label : labels) label = std::min(label, 1u);
  const Skeleton halves = extract_skeleton(mesh, labels, std::vector<Primitive>(2));
  ASSERT_EQ(halves.joints.size(), 3u);
  EXPECT_EQ(halves.joints[0].kind, JointKind::Sensitive);
  EXPECT_NEAR(halves.joints[0].position[0], 0.5, 1e-12);
  EXPECT_EQ(halves.joints[1].kind, JointKind::Virtual);
  EXPECT_EQ(halves.joints[2].kind, JointKind::Virtual);
  for (const Bone& bone : halves.bones) EXPECT_TRUE(bone.visible);
}

TEST(Skeleton, AnIsolatedClusterGetsAVirtualJointAtEachEnd) {
  const FigureSkeleton& s = figure_skeleton();
  const Skeleton one = extract_skeleton(s.hierarchy, cut_by_count(s.hierarchy, 1));
  ASSERT_EQ(one.joints.size(), 2u);
  for (const Joint& joint : one.joints) EXPECT_EQ(joint.kind, JointKind::Virtual);
  EXPECT_GT(distance(one.joints[0].position, one.joints[1].position), 1.0);
}

TEST(Skeleton, ABoneOfAPlaneRunsAlongItsLongestExtent) {
  // A flat strip 1 wide and 10 long along y, tilted 30 degrees about y, fitted as a plane: the
  // bone follows the strip's length, through its middle, with its ends at the strip's ends.
  const double tilt = std::numbers::pi / 6;
  const Mesh strip = testing::grid_mesh(
      4, 40,
      [&](double u, double v) {
        return Vec3{u * std::cos(tilt), 10 * v, u * std::sin(tilt)};
      },
      /*alternate=*/true);
  Primitive plane;
  plane.type = PrimitiveType::Plane;
  plane.axis = {-std::sin(tilt), 0, std::cos(tilt)};
  plane.point = {0, 0, 0};
  const Skeleton skeleton =
      extract_skeleton(strip, std::vector<std::uint32_t>(strip.face_count(), 0), {&plane, 1});
  ASSERT_EQ(skeleton.bones.size(), 1u);
  const Bone& bone = skeleton.bones[0];
  EXPECT_NEAR(bone.axis[0], 0, 1e-12);
  EXPECT_NEAR(bone.axis[1], 1, 1e-12);
  EXPECT_NEAR(bone.axis[2], 0, 1e-12);
  EXPECT_NEAR(bone.point[0], 0.5 * std::cos(tilt), 1e-12);
  EXPECT_NEAR(bone.point[2], 0.5 * std::sin(tilt), 1e-12);
  EXPECT_NEAR(bone.area, 10, 1e-12);
  ASSERT_EQ(skeleton.joints.size(), 2u);
  EXPECT_NEAR(distance(skeleton.joints[0].position, skeleton.joints[1].position), 10, 1e-9);
}

TEST(Skeleton, BadInputIsRejected) {
  const Mesh mesh = testing::grid_mesh(2, 2, [](double u, double v) { return Vec3{u, v, 0}; });
  const std::vector<Primitive> two(2);
  EXPECT_THROW(extract_skeleton(mesh, std::vector<std::uint32_t>(3, 0), two), InvalidInputError);
  EXPECT_THROW(extract_skeleton(mesh, std::vector<std::uint32_t>(8, 0), two), InvalidInputError)
      << "cluster 1 has no face";
  EXPECT_THROW(extract_skeleton(mesh, std::vector<std::uint32_t>(8, 2), two), InvalidInputError);
  // A mesh edited by hand into an inconsistent one is refused before any geometry is read.
  const std::vector<std::uint32_t> halves{0, 0, 0, 0, 1, 1, 1, 1};
  EXPECT_NO_THROW(extract_skeleton(mesh, halves, two));
  Mesh unknown_vertex = mesh;
  unknown_vertex.triangles[5][1] = static_cast<std::uint32_t>(mesh.vertex_count());
  EXPECT_THROW(extract_skeleton(unknown_vertex, halves, two), InvalidInputError);
  Mesh unmapped_triangle = mesh;
  unmapped_triangle.face_of_triangle.pop_back();
  EXPECT_THROW(extract_skeleton(unmapped_triangle, halves, two), InvalidInputError);
}

// A skeleton of another mesh (or edited) is refused by what uses its face labels, naming the
// function and what is wrong.
TEST(Skeleton, UsesRefuseASkeletonOfAnotherMesh) {
  const FigureSkeleton& s = figure_skeleton();
  Skeleton fewer = s.skeleton, beyond = s.skeleton;
  fewer.face_labels.pop_back();
  beyond.face_labels[7] = static_cast<std::uint32_t>(beyond.bones.size());
  const SkinWeights weights = compute_skin_weights(s.figure.mesh, s.skeleton);
  const std::vector<std::pair<std::string, std::function<void(const Skeleton&)>>> uses = {
      {"compute_skin_weights", [&](const Skeleton& k) { compute_skin_weights(s.figure.mesh, k); }},
      {"render_skeleton", [&](const Skeleton& k) { render_skeleton(s.figure.mesh, k); }},
      {"glTF skin", [&](const Skeleton& k) { skinned_glb(s.figure.mesh, k, weights); }}};
  for (const auto& [name, use] : uses)
    for (const auto& [skeleton, message] :
         {std::pair{&fewer, "the skeleton has " + std::to_string(fewer.face_labels.size()) +
                                " face labels for " + std::to_string(s.figure.mesh.face_count()) +
                                " faces"},
          std::pair{&beyond, "face 7 has label " + std::to_string(beyond.bones.size()) +
                                 ", not one of the " + std::to_string(beyond.bones.size()) +
                                 " bones"}}) {
      try {
        use(*skeleton);
        ADD_FAILURE() << name << " accepted: " << message;
      } catch (const InvalidInputError& e) {
        EXPECT_EQ(std::string(e.what()), name + ": " + message);
      }
    }
}

TEST(Skeleton, IsDeterministic) {
  const FigureSkeleton& s = figure_skeleton();
  const Skeleton again = extract_skeleton(s.hierarchy, s.level);
  ASSERT_EQ(again.joints.size(), s.skeleton.joints.size());
  for (std::size_t j = 0; j < again.joints.size(); ++j) {
    EXPECT_EQ(again.joints[j].position, s.skeleton.joints[j].position);
    EXPECT_EQ(again.joints[j].bones, s.skeleton.joints[j].bones);
  }
}

TEST(SkeletonRender, DrawsJointsInTheirColoursWhereTheyProject) {
  const FigureSkeleton& s = figure_skeleton();
  RenderOptions options;
  options.width = 320;
  options.height = 240;
  const auto rgb = render_skeleton(s.figure.mesh, s.skeleton, options);
  ASSERT_EQ(rgb.size(), 320u * 240u * 3u);
  std::vector<Vec3> positions;
  for (const Joint& joint : s.skeleton.joints) positions.push_back(joint.position);
  const auto pixels = project_to_picture(s.figure.mesh, positions, options);
  for (const Joint& joint : s.skeleton.joints) {
    const int x = static_cast<int>(pixels[joint.id][0]), y = static_cast<int>(pixels[joint.id][1]);
    ASSERT_TRUE(x >= 0 && x < 320 && y >= 0 && y < 240);
    const std::size_t at = (static_cast<std::size_t>(y) * 320 + static_cast<std::size_t>(x)) * 3;
    if (joint.kind == JointKind::Virtual)
      EXPECT_GT(rgb[at + 2], 150) << "virtual joints are blue";
    else
      EXPECT_GT(rgb[at], 150) << "sensitive joints are red";
  }
}

// A locked joint (a hub where touching boundaries met, as a skeleton file may list one) is a grey
// square in a dark frame: square, so its frame reaches the corners a disc would leave out.
TEST(SkeletonRender, DrawsALockedJointAsAGreySquareInADarkFrame) {
  const FigureSkeleton& s = figure_skeleton();
  Skeleton skeleton = s.skeleton;
  const auto visible = std::find_if(skeleton.joints.begin(), skeleton.joints.end(),
                                    [](const Joint& joint) { return joint.visible; });
  ASSERT_NE(visible, skeleton.joints.end());
  visible->kind = JointKind::Locked;
  RenderOptions options;
  options.width = 640;
  options.height = 480;
  const auto rgb = render_skeleton(s.figure.mesh, skeleton, options);
  const std::vector<Vec3> joint{visible->position};
  const auto pixel = project_to_picture(s.figure.mesh, joint, options)[0];
  const auto colour_at = [&](int dx, int dy) {
    const std::size_t x = static_cast<std::size_t>(std::floor(pixel[0]) + dx);
    const std::size_t y = static_cast<std::size_t>(std::floor(pixel[1]) + dy);
    const std::size_t at = (y * static_cast<std::size_t>(options.width) + x) * 3;
    return std::array<int, 3>{rgb[at], rgb[at + 1], rgb[at + 2]};
  };
  // The inner square has a half side of 3 pixels, the frame 4.5 (at this size).
  EXPECT_EQ(colour_at(0, 0), (std::array<int, 3>{110, 110, 110}));
  EXPECT_EQ(colour_at(4, 4), (std::array<int, 3>{25, 25, 25}));
  EXPECT_EQ(colour_at(-4, -4), (std::array<int, 3>{25, 25, 25}));
}

}  // namespace
}  // namespace primseg
