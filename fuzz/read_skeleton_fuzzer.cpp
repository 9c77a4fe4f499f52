// libFuzzer target for the skeleton and pose files (skeleton_io.hpp), which `primseg deform` reads
// from users. The same bytes are read as both. Checked:
// - parse_skeleton_json and parse_pose_json accept the text or throw ParseError, nothing else;
// - an accepted skeleton is one the rest of the library can use: ids in order, joints and bones
//   listing each other, labels below K, finite positions; writing it and reading it back gives
//   the same text (one spelling per skeleton);
// - an accepted pose has finite axes and angles, and pose_bones on the accepted skeleton either
//   gives finite rigid motions or throws InvalidInputError (unknown, locked, repeated joints...).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "primseg/error.hpp"
#include "primseg/skeleton_io.hpp"
#include "primseg/skinning.hpp"
#include "tree_invariants.hpp"

namespace {

using namespace primseg;

void check_finite(const Vec3& v, const char* what) {
  for (const double x : v)
    if (!std::isfinite(x)) fuzz::fail(what, x);
}

void check_skeleton(const Skeleton& skeleton) {
  const std::size_t k = skeleton.bones.size(), joints = skeleton.joints.size();
  if (k == 0) fuzz::fail("a skeleton without bones");
  for (std::size_t j = 0; j < joints; ++j) {
    const Joint& joint = skeleton.joints[j];
    if (joint.id != j) fuzz::fail("joint id", double(joint.id));
    check_finite(joint.position, "joint position");
    for (const std::uint32_t b : joint.bones) {
      if (b >= k) fuzz::fail("joint's bone", b);
      const auto& back = skeleton.bones[b].joints;
      if (std::find(back.begin(), back.end(), joint.id) == back.end())
        fuzz::fail("a bone does not list its joint", b);
    }
  }
  for (std::size_t b = 0; b < k; ++b) {
    const Bone& bone = skeleton.bones[b];
    if (bone.id != b) fuzz::fail("bone id", double(bone.id));
    check_finite(bone.axis, "bone axis");
    check_finite(bone.point, "bone point");
    if (!(std::isfinite(bone.radius) && bone.radius >= 0)) fuzz::fail("bone radius", bone.radius);
    for (const std::uint32_t j : bone.joints)
      if (j >= joints) fuzz::fail("bone's joint", j);
  }
  for (const std::uint32_t label : skeleton.face_labels)
    if (label >= k) fuzz::fail("face label", label);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::optional<Skeleton> skeleton;
  try {
    skeleton = parse_skeleton_json(text, "fuzz.json");
  } catch (const ParseError&) {
  }
  if (skeleton) {
    check_skeleton(*skeleton);
    const std::string written = skeleton_json(*skeleton);
    if (skeleton_json(parse_skeleton_json(written)) != written)
      fuzz::fail("a written skeleton reads back differently");
  }
  std::optional<std::vector<JointRotation>> pose;
  try {
    pose = parse_pose_json(text, "fuzz.json");
  } catch (const ParseError&) {
  }
  if (pose) {
    for (const JointRotation& rotation : *pose) {
      check_finite(rotation.axis, "pose axis");
      if (!std::isfinite(rotation.angle)) fuzz::fail("pose angle", rotation.angle);
    }
    if (skeleton) {
      try {
        for (const RigidTransform& motion : pose_bones(*skeleton, *pose)) {
          check_finite(motion.translation, "bone translation");
          for (const auto& row : motion.rotation)
            for (const double x : row)
              if (!std::isfinite(x)) fuzz::fail("bone rotation", x);
        }
      } catch (const InvalidInputError&) {
      }
    }
  }
  return 0;
}
