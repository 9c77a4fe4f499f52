#include "primseg/skeleton_io.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "file_io.hpp"
#include "json_document.hpp"
#include "primseg/error.hpp"
#include "skeleton_file.hpp"

namespace primseg {
namespace {

using nlohmann::json;

// Parses JSON text; ParseError with the name on malformed text.
json parse_text(std::string_view text, const std::string& name) {
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    throw ParseError("'" + name + "': not valid JSON: " + e.what());
  }
}

Vec3 read_vec(const json& value, const std::string& what) {
  if (!value.is_array() || value.size() != 3)
    throw InvalidInputError(what + " must be an array of 3 numbers");
  Vec3 v{};
  for (int i = 0; i < 3; ++i) {
    if (!value[i].is_number()) throw InvalidInputError(what + " must be an array of 3 numbers");
    v[i] = value[i].get<double>();
    if (!std::isfinite(v[i])) throw InvalidInputError(what + " must be finite");
  }
  return v;
}

std::uint32_t read_index(const json& value, const std::string& what, std::size_t limit) {
  if (!value.is_number_unsigned() || value.get<std::uint64_t>() >= limit)
    throw InvalidInputError(what + " must be an integer in 0.." +
                            std::to_string(limit == 0 ? 0 : limit - 1));
  return static_cast<std::uint32_t>(value.get<std::uint64_t>());
}

const json& member(const json& object, const char* key, const std::string& where) {
  if (!object.is_object() || !object.contains(key))
    throw InvalidInputError(where + ": missing \"" + key + "\"");
  return object.at(key);
}

}  // namespace

namespace detail {

std::string skeleton_file_text(const Skeleton& skeleton, json summary) {
  summary["cluster_count"] = skeleton.cluster_count();
  summary["root_bone"] = skeleton.root_bone();
  summary["face_labels"] = skeleton.face_labels;
  summary["joints"] = json::array();
  summary["bones"] = json::array();
  // A bone per cluster: a level of many (a triangle soup's) held about 4 KB per bone as a
  // document.
  const StreamedArray arrays[] = {{"joints", skeleton.joints.size(),
                                   [&skeleton](std::size_t i) {
                                     const Joint& j = skeleton.joints[i];
                                     return json{{"id", j.id},
                                                 {"position", vec3_json(j.position)},
                                                 {"kind", std::string(to_string(j.kind))},
                                                 {"visible", j.visible},
                                                 {"bones", j.bones}};
                                   }},
                                  {"bones", skeleton.bones.size(), [&skeleton](std::size_t i) {
                                     const Bone& b = skeleton.bones[i];
                                     return json{{"id", b.id},
                                                 {"cluster", b.cluster},
                                                 {"joints", b.joints},
                                                 {"visible", b.visible},
                                                 {"axis", vec3_json(b.axis)},
                                                 {"point", vec3_json(b.point)},
                                                 {"radius", b.radius},
                                                 {"area", b.area}};
                                   }}};
  return dump_document(summary, arrays);
}

}  // namespace detail

Skeleton parse_skeleton_json(std::string_view text, const std::string& name) {
  const json root = parse_text(text, name);
  try {
    Skeleton skeleton;
    const json& bones = member(root, "bones", "skeleton");
    const json& joints = member(root, "joints", "skeleton");
    if (!bones.is_array() || bones.empty() || !joints.is_array())
      throw InvalidInputError("\"bones\" must be a non-empty array and \"joints\" an array");
    const std::size_t k = bones.size(), joint_count = joints.size();
    for (std::size_t i = 0; i < k; ++i) {
      const std::string where = "bone " + std::to_string(i);
      Bone bone;
      bone.id = read_index(member(bones[i], "id", where), where + " id", k);
      if (bone.id != i) throw InvalidInputError(where + ": ids must be 0..K-1 in order");
      bone.cluster = bone.id;
      for (const json& j : member(bones[i], "joints", where))
        bone.joints.push_back(read_index(j, where + " joint", joint_count));
      bone.visible = member(bones[i], "visible", where).get<bool>();
      bone.axis = read_vec(member(bones[i], "axis", where), where + " axis");
      bone.point = read_vec(member(bones[i], "point", where), where + " point");
      bone.radius = member(bones[i], "radius", where).get<double>();
      if (!(std::isfinite(bone.radius) && bone.radius >= 0))
        throw InvalidInputError(where + ": radius must be finite and >= 0");
      bone.area = member(bones[i], "area", where).get<double>();
      if (!(std::isfinite(bone.area) && bone.area >= 0))
        throw InvalidInputError(where + ": area must be finite and >= 0");
      skeleton.bones.push_back(std::move(bone));
    }
    for (std::size_t i = 0; i < joint_count; ++i) {
      const std::string where = "joint " + std::to_string(i);
      Joint joint;
      joint.id = read_index(member(joints[i], "id", where), where + " id", joint_count);
      if (joint.id != i) throw InvalidInputError(where + ": ids must be 0..J-1 in order");
      joint.position = read_vec(member(joints[i], "position", where), where + " position");
      const auto kind = joint_kind_from_string(member(joints[i], "kind", where).get<std::string>());
      if (!kind) throw InvalidInputError(where + ": unknown kind");
      joint.kind = *kind;
      joint.visible = member(joints[i], "visible", where).get<bool>();
      for (const json& b : member(joints[i], "bones", where))
        joint.bones.push_back(read_index(b, where + " bone", k));
      if (joint.bones.empty()) throw InvalidInputError(where + ": no bone");
      skeleton.joints.push_back(std::move(joint));
    }
    // Every joint lists its bones and every bone its joints: both sides must agree.
    for (const Joint& joint : skeleton.joints)
      for (const std::uint32_t b : joint.bones) {
        const auto& list = skeleton.bones[b].joints;
        if (std::find(list.begin(), list.end(), joint.id) == list.end())
          throw InvalidInputError("joint " + std::to_string(joint.id) + " lists bone " +
                                  std::to_string(b) + ", which does not list it");
      }
    for (const Bone& bone : skeleton.bones)
      for (const std::uint32_t j : bone.joints) {
        const auto& list = skeleton.joints[j].bones;
        if (std::find(list.begin(), list.end(), bone.id) == list.end())
          throw InvalidInputError("bone " + std::to_string(bone.id) + " lists joint " +
                                  std::to_string(j) + ", which does not list it");
      }
    for (const json& label : member(root, "face_labels", "skeleton"))
      skeleton.face_labels.push_back(read_index(label, "face label", k));
    if (read_index(member(root, "root_bone", "skeleton"), "root_bone", k) != skeleton.root_bone())
      throw InvalidInputError("root_bone must be 0 (the largest bone)");
    return skeleton;
  } catch (const json::exception& e) {
    throw ParseError("'" + name + "': not a skeleton file: " + e.what());
  } catch (const InvalidInputError& e) {
    throw ParseError("'" + name + "': not a skeleton file: " + e.what());
  }
}

std::string skeleton_json(const Skeleton& skeleton) {
  return detail::skeleton_file_text(skeleton, json::object());
}

Skeleton read_skeleton(const std::filesystem::path& path) {
  const detail::FileImage image = detail::read_file(path);
  return parse_skeleton_json(image.view(), path.string());
}

void write_skeleton(const std::filesystem::path& path, const Skeleton& skeleton) {
  detail::write_file_atomically(path, skeleton_json(skeleton));
}

std::vector<JointRotation> parse_pose_json(std::string_view text, const std::string& name) {
  const json root = parse_text(text, name);
  try {
    std::vector<JointRotation> pose;
    const json& rotations = member(root, "rotations", "pose");
    if (!rotations.is_array()) throw InvalidInputError("\"rotations\" must be an array");
    for (std::size_t i = 0; i < rotations.size(); ++i) {
      const std::string where = "rotation " + std::to_string(i);
      JointRotation rotation;
      rotation.joint = read_index(member(rotations[i], "joint", where), where + " joint",
                                  std::numeric_limits<std::uint32_t>::max());
      rotation.axis = read_vec(member(rotations[i], "axis", where), where + " axis");
      const json& degrees = member(rotations[i], "degrees", where);
      if (!degrees.is_number() || !std::isfinite(degrees.get<double>()))
        throw InvalidInputError(where + ": degrees must be a finite number");
      // (π / 180) first: finite for every finite number of degrees.
      rotation.angle = degrees.get<double>() * (std::numbers::pi / 180);
      pose.push_back(rotation);
    }
    return pose;
  } catch (const json::exception& e) {
    throw ParseError("'" + name + "': not a pose file: " + e.what());
  } catch (const InvalidInputError& e) {
    throw ParseError("'" + name + "': not a pose file: " + e.what());
  }
}

std::vector<JointRotation> read_pose(const std::filesystem::path& path) {
  const detail::FileImage image = detail::read_file(path);
  return parse_pose_json(image.view(), path.string());
}

}  // namespace primseg
