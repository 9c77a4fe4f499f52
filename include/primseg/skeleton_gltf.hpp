#pragma once
/// @file skeleton_gltf.hpp
/// A rigged mesh as a binary glTF 2.0 file (GLB): the mesh skinned to its skeleton
/// (skeleton.hpp) with its skin weights (skinning.hpp), for Blender, three.js, game engines and
/// any other tool that reads glTF skins. Posing it there moves the vertices as
/// `primseg deform` does (skinning.hpp's pose semantics map onto glTF's node rotations exactly).
///
/// Layout of the file:
/// - node 0, "mesh": the triangles (input units, float32 positions relative to the centre of the
///   mesh's bounding box, bounding_box_centre(); area-weighted vertex normals), with attributes
///   JOINTS_n / WEIGHTS_n.
///   Triangles are consistently oriented (outward on a closed part) whatever way the input lists
///   them, since readers cull back faces: a triangle the dual graph flips (DualGraph::flipped) is
///   written with its last two corners swapped;
/// - node 1, "skeleton": the common root of the joints, translated to that centre (so skinning
///   puts every vertex back where the input has it, and float32 holds a part far from the origin,
///   such as a scan in survey coordinates, as finely as one at it);
/// - nodes 2 .. 2+K-1, "bone_b": one per bone in bone id order, arranged as bone_tree() arranges
///   them. Bone b's node sits at its pivot: the joint it hangs from (BoneTree::parent_joint), or
///   its axis point (Bone::point) for a root bone. The node's `extras` give {"bone": b, "joint":
///   the primseg joint it pivots on or null, "joint_kind": "sensitive", "locked" or null}.
///   Rotating bone b's node by a quaternion is JointRotation{joint, axis, angle} on that joint,
///   with the axis in the parent bone's frame, as skinning.hpp defines it.
/// - then one "end_j" node per virtual joint j (the free end of a limb), a child of its bone's
///   node, with no weights: importers such as Blender's use it for the bone's length and
///   direction.
/// Skin joint i is node 2 + i; inverse bind matrices translate each pivot (relative to the centre)
/// to the origin.

#include <cstdint>
#include <string>

#include "primseg/mesh.hpp"
#include "primseg/skeleton.hpp"
#include "primseg/skinning.hpp"

namespace primseg {

struct GltfOptions {
  /// Most bones per vertex. 0 keeps every weight, in as many JOINTS_n / WEIGHTS_n sets of four as
  /// the widest row needs (the largest weights in set 0: a reader that reads set 0 alone, as
  /// three.js does, renormalises them). N > 0 keeps each vertex's N largest weights, rescaled to
  /// sum to 1 (4 for engines that take four influences only).
  std::uint32_t max_influences = 0;
};

/// The GLB file's bytes. Weights are written in float32 rows summing to exactly 1 (each row's
/// weights after its largest rounded to multiples of 2^-24, below which they are left out; the
/// largest takes the rest), joint indices as unsigned 16-bit integers (so at most 65,536 bones
/// and end joints).
/// A vertex used by no triangle (an empty weight row) follows the root bone.
///
/// `skeleton` must have been made from `mesh` and `weights` from both (compute_skin_weights).
/// Throws InvalidInputError when the sizes disagree, a weight is out of range, or the skeleton has
/// too many bones for a glTF skin.
std::string skinned_glb(const Mesh& mesh, const Skeleton& skeleton, const SkinWeights& weights,
                        const GltfOptions& options = {});

}  // namespace primseg
