#pragma once
/// @file skinning.hpp
/// Skinning weights of a mesh to its skeleton (skeleton.hpp), poses (rotations about joints) and
/// linear blend skinning. Everything here is cheap enough to run on every mouse move of a viewer:
/// weights once per skeleton, then pose_bones() and skin_positions() per pose.
///
/// Weights (a partition of unity): a vertex inside a cluster, farther than the band from every
/// boundary of its cluster, follows its cluster's bone alone. Near the boundary with a
/// neighbouring cluster, at a distance d inside its cluster (along mesh edges), it gives the
/// neighbour's bone the weight (1 − s(d / band)) / 2, s the smoothstep 3t² − 2t³, and its own bone
/// the rest: 1/2 and 1/2 on the boundary, 1 and 0 at the band's edge, smooth in between. The
/// band is SkinningOptions::band times the cluster's bone radius. A vertex on several clusters
/// (a boundary vertex) averages the weights seen from each of them, weighted by its triangles in
/// each: the weights are continuous across boundaries.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "primseg/mesh.hpp"
#include "primseg/skeleton.hpp"

namespace primseg {

struct SkinningOptions {
  /// Half-width of the blend band on each side of a boundary, as a multiple of the radius of the
  /// vertex's own bone (Bone::radius). 0: every vertex follows its cluster's bone alone (boundary
  /// vertices half and half). Finite, >= 0.
  double band = 0.5;
};

/// Skinning weights, one sparse row per mesh vertex (compressed rows).
struct SkinWeights {
  /// Row starts, shape (n + 1) for n vertices.
  std::vector<std::uint32_t> offsets{0};
  /// Bone ids of all rows, increasing within a row.
  std::vector<std::uint32_t> bones;
  /// Weights of all rows, in (0, 1], each row summing to 1 (an isolated vertex, used by no
  /// triangle, has an empty row and never moves).
  std::vector<double> weights;

  std::uint32_t vertex_count() const { return static_cast<std::uint32_t>(offsets.size() - 1); }
  /// The bones and weights of one vertex's row (vertex < vertex_count(), not checked).
  std::span<const std::uint32_t> bones_of(std::uint32_t vertex) const {
    return {bones.data() + offsets[vertex], bones.data() + offsets[vertex + 1]};
  }
  std::span<const double> weights_of(std::uint32_t vertex) const {
    return {weights.data() + offsets[vertex], weights.data() + offsets[vertex + 1]};
  }
};

/// Weights of every vertex of `mesh` to the bones of `skeleton` (made from this mesh). Throws
/// InvalidInputError when the skeleton's labels do not match the mesh or the options are out of
/// range.
SkinWeights compute_skin_weights(const Mesh& mesh, const Skeleton& skeleton,
                                 const SkinningOptions& options = {});

/// A rotation about a joint: the part of the skeleton beyond the joint (away from the root bone)
/// turns by `angle` radians about the line through the joint's rest position with direction
/// `axis` (right-hand rule). The axis is in rest-pose coordinates of the part before the joint:
/// rotations of joints nearer the root carry it along.
struct JointRotation {
  std::uint32_t joint = 0;
  Vec3 axis{0, 0, 1};  ///< non-zero, any length
  double angle = 0;    ///< radians
};

/// x -> rotation * x + translation.
struct RigidTransform {
  /// Row-major 3 × 3 rotation matrix.
  std::array<std::array<double, 3>, 3> rotation{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  Vec3 translation{0, 0, 0};

  Vec3 apply(const Vec3& x) const;
  /// this ∘ other: apply `other` first.
  RigidTransform operator*(const RigidTransform& other) const;
  /// Rotation by `angle` radians about the line through `centre` with direction `axis`.
  static RigidTransform rotation_about(const Vec3& centre, const Vec3& axis, double angle);
};

/// The bones of the skeleton in the order a pose visits them (breadth-first from the root bone
/// over shared joints, lower ids first), each with the joint it hangs from.
struct BoneTree {
  std::vector<std::uint32_t> order;         ///< bone ids, root first, shape (K)
  std::vector<std::uint32_t> parent_joint;  ///< per bone id, UINT32_MAX for roots
  std::vector<std::uint32_t> parent_bone;   ///< per bone id, UINT32_MAX for roots
};

/// The tree a pose uses. Bones not connected to the root bone (other connected components) are
/// roots of their own trees and never move. Where the skeleton has a cycle, the breadth-first
/// tree drops one of its joints, which then cannot be rotated.
BoneTree bone_tree(const Skeleton& skeleton);

/// Ids of the bones that move when `joint` is rotated, increasing. Throws InvalidInputError
/// unless the joint is sensitive and is in the bone tree.
std::vector<std::uint32_t> bones_beyond(const Skeleton& skeleton, std::uint32_t joint);

/// The rigid motion of every bone (shape (K)) for a pose: each rotated joint carries every bone
/// beyond it. Throws InvalidInputError for an unknown joint, a joint that is not sensitive, one
/// given twice, one not in the bone tree (on a cycle), a zero or non-finite axis or angle.
std::vector<RigidTransform> pose_bones(const Skeleton& skeleton,
                                       std::span<const JointRotation> pose);

/// Linear blend skinning: x' = Σ_b w_b T_b(x), shape (n). A vertex whose bones all have the same
/// transform gets exactly T(x), so what a pose does not move stays bit for bit in place. Throws
/// InvalidInputError when the sizes disagree.
std::vector<Vec3> skin_positions(std::span<const Vec3> rest, const SkinWeights& weights,
                                 std::span<const RigidTransform> bone_transforms);

/// Joint positions in a pose: a joint moves with the bone it hangs from nearest the root.
std::vector<Vec3> posed_joint_positions(const Skeleton& skeleton,
                                        std::span<const RigidTransform> bone_transforms);

/// One shot: weights, pose and skinning; returns the mesh with moved vertices (same faces).
Mesh deform(const Mesh& mesh, const Skeleton& skeleton, std::span<const JointRotation> pose,
            const SkinningOptions& options = {});

}  // namespace primseg
