#pragma once
/// @file skeleton.hpp
/// A deformation skeleton from one level of the hierarchy (Attene, Falcidieno and Spagnuolo
/// 2006, section 7): the dual of the cluster adjacency graph. Each cluster is a bone; each pair
/// of adjacent clusters gives a joint at the centroid of their shared boundary, and pair joints
/// whose boundaries touch merge into one joint of three or more bones. With cylinders only, the
/// clusters of a natural shape (a person, an animal) are its limbs and trunk, and the skeleton
/// is the one an animator would draw.
///
/// One-shot use: `Skeleton s = extract_skeleton(hierarchy, cut_by_count(hierarchy, 12));`.

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "primseg/cut.hpp"
#include "primseg/mesh.hpp"
#include "primseg/primitive.hpp"

namespace primseg {

/// What a joint allows (the paper's rules).
enum class JointKind : std::uint8_t {
  /// At most two incident bones: the bones may rotate about it.
  Sensitive = 0,
  /// Three or more incident bones (a hub where several clusters meet), or, with
  /// JointRule::Limbs, a joint of two that touches a limb's attachment: not movable.
  Locked = 1,
  /// The free end of a bone adjacent to only one other (a hand, a foot): a movable end.
  Virtual = 2,
};

/// "sensitive", "locked" or "virtual".
std::string_view to_string(JointKind kind);
/// Inverse of to_string; std::nullopt for an unknown name.
std::optional<JointKind> joint_kind_from_string(std::string_view name);

struct Joint {
  std::uint32_t id = 0;
  Vec3 position{0, 0, 0};  ///< input units
  JointKind kind = JointKind::Sensitive;
  /// False when every incident bone is hidden.
  bool visible = true;
  /// Incident bones, increasing ids.
  std::vector<std::uint32_t> bones;
};

struct Bone {
  std::uint32_t id = 0;
  /// Cluster of the segmentation (its label); bone ids equal cluster labels.
  std::uint32_t cluster = 0;
  /// Joints of the bone, increasing ids: two for a limb segment, more for a hub, one virtual
  /// joint at the free end of a bone with a single neighbour.
  std::vector<std::uint32_t> joints;
  /// False when every joint of the bone is locked (a bone in the middle of a hub).
  bool visible = true;
  /// Unit direction of the bone: the cluster's cylinder axis when it was fitted with a cylinder,
  /// else the principal direction of its surface (largest-magnitude component positive).
  Vec3 axis{0, 0, 0};
  /// A point of that axis: the area-weighted centroid of the cluster projected on it.
  Vec3 point{0, 0, 0};
  /// The cylinder's radius, else the mean distance of the cluster's vertices to the axis
  /// (input units).
  double radius = 0;
  /// Area of the cluster (input units²).
  double area = 0;
};

/// Which boundaries become movable joints.
enum class JointRule : std::uint8_t {
  /// The paper's: pair joints whose boundaries touch merge, so a limb meeting two or more
  /// clusters of a bulky body (a leg on a trunk split into patches) joins a locked hub.
  Paper = 0,
  /// The paper's, except that a limb gets a sensitive joint where it is attached: see
  /// SkeletonOptions::limb_protrusion.
  Limbs = 1,
};

/// "paper" or "limbs".
std::string_view to_string(JointRule rule);
/// Inverse of to_string; std::nullopt for an unknown name.
std::optional<JointRule> joint_rule_from_string(std::string_view name);

struct SkeletonOptions {
  /// Default: the paper's rule, as the format and the pictures document it.
  JointRule joints = JointRule::Paper;
  /// JointRule::Limbs: a cluster is a limb when its boundary has one loop on the root bone's
  /// side (cutting it there frees the cluster and everything beyond its other loops), and its
  /// own vertices reach farther from that loop's plane than this many times the loop's mean
  /// radius (1: a hemisphere; a gently curved patch of a trunk stays below). Limbs are taken
  /// by decreasing protrusion; one whose loop shares a boundary with a limb already taken is
  /// not one. Dimensionless, >= 0.
  double limb_protrusion = 1.0;
};

/// A skeleton and the segmentation it was made from.
struct Skeleton {
  std::vector<Joint> joints;
  /// One bone per cluster, shape (K), bone i is cluster i.
  std::vector<Bone> bones;
  /// Cluster (bone) of each input face, shape (F).
  std::vector<std::uint32_t> face_labels;
  std::uint32_t cluster_count() const { return static_cast<std::uint32_t>(bones.size()); }
  /// The bone that stays still when a joint is rotated: the largest by area (cluster 0, as
  /// clusters are numbered by decreasing area).
  std::uint32_t root_bone() const { return 0; }
};

/// Builds the skeleton of a segmentation of `mesh`.
///
/// `face_labels`: cluster of each input face, shape (F), values 0..K-1 with every value used,
/// clusters numbered by decreasing area as cut.hpp does. `primitives`: the fitted primitive of
/// each cluster, shape (K), input units (describe_clusters gives them).
///
/// Rules:
/// - Two clusters are adjacent when a mesh edge has triangles of both. Their joint is the
///   length-weighted centroid of the edges they share (their boundary).
/// - Pair joints whose boundaries share a vertex (where three or more clusters meet) are one
///   joint: the centroid of all their boundary edges, incident to all their bones.
/// - A cluster adjacent to exactly one other gets a virtual joint at its far end: on its axis,
///   at the extent of its vertices on the side away from its joint. An isolated cluster (no
///   neighbour) gets two virtual joints, at both extents.
/// - Kinds: at most two bones: sensitive; more: locked; free ends: virtual. A bone whose joints
///   are all locked is hidden; a joint whose bones are all hidden is hidden.
/// - JointRule::Limbs first takes each limb's attachment loop out of that merging: one sensitive
///   joint at the loop's length-weighted centroid, its bones the limb and the neighbour it
///   shares the longest boundary with (the bone it turns against). A joint of the remaining
///   boundaries that touches a limb's loop is locked: the clusters a limb hangs from stay rigid
///   together, as the paper's hub held them.
/// Joints are numbered by their lowest boundary vertex (virtual joints after the others, by
/// bone), so the result is deterministic. Throws InvalidInputError when the sizes disagree, a
/// label is out of range or unused, or limb_protrusion is negative or not finite.
Skeleton extract_skeleton(const Mesh& mesh, std::span<const std::uint32_t> face_labels,
                          std::span<const Primitive> primitives,
                          const SkeletonOptions& options = {});

/// The skeleton of a level of a hierarchy.
Skeleton extract_skeleton(const Hierarchy& hierarchy, const Segmentation& segmentation,
                          const SkeletonOptions& options = {});

}  // namespace primseg
