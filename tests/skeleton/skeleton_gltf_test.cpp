// The rigged mesh as binary glTF (skeleton_gltf.hpp), read back here by the rules of the glTF 2.0
// specification: the container, the accessors, the weights, and skinning through the node
// hierarchy, which must pose the mesh as pose_bones() and skin_positions() do. (web/test/
// gltf.test.mjs also reads the file with the Khronos validator and with three.js.)

#include "primseg/skeleton_gltf.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>

#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "support/stick_figure.hpp"

namespace primseg {
namespace {

using nlohmann::json;
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

std::uint32_t u32_at(const std::string& bytes, std::size_t offset) {
  std::uint32_t value = 0;
  std::memcpy(&value, bytes.data() + offset, 4);
  return value;
}

// A GLB file taken apart: its JSON and its binary chunk, with typed access to accessors.
struct Glb {
  json gltf;
  std::string bin;

  explicit Glb(const std::string& bytes) {
    EXPECT_EQ(u32_at(bytes, 0), 0x46546C67u);  // "glTF"
    EXPECT_EQ(u32_at(bytes, 4), 2u);
    EXPECT_EQ(u32_at(bytes, 8), bytes.size());
    const std::uint32_t json_length = u32_at(bytes, 12);
    EXPECT_EQ(u32_at(bytes, 16), 0x4E4F534Au);  // "JSON"
    EXPECT_EQ(json_length % 4, 0u);
    gltf = json::parse(bytes.substr(20, json_length));
    const std::size_t bin_header = 20 + json_length;
    const std::uint32_t bin_length = u32_at(bytes, bin_header);
    EXPECT_EQ(u32_at(bytes, bin_header + 4), 0x004E4942u);  // "BIN\0"
    EXPECT_EQ(bin_header + 8 + bin_length, bytes.size());
    bin = bytes.substr(bin_header + 8, bin_length);
    EXPECT_EQ(gltf["buffers"][0]["byteLength"], bin.size());
  }

  // Accessor `index` as `T` values, checking that it lies in the buffer with the given layout.
  template <class T>
  std::vector<T> read(std::size_t index, int component_type, const std::string& type,
                      std::size_t components) const {
    const json& accessor = gltf["accessors"][index];
    EXPECT_EQ(accessor["componentType"], component_type);
    EXPECT_EQ(accessor["type"], type);
    const json& view = gltf["bufferViews"][accessor["bufferView"].get<std::size_t>()];
    const std::size_t count = accessor["count"], offset = view["byteOffset"];
    const std::size_t bytes = count * components * sizeof(T);
    EXPECT_EQ(view["byteLength"], bytes);
    EXPECT_EQ(offset % 4, 0u);
    EXPECT_LE(offset + bytes, bin.size());
    std::vector<T> values(count * components);
    if (offset + bytes <= bin.size() && bytes > 0) std::memcpy(values.data(), &bin[offset], bytes);
    return values;
  }
};

// A glTF node's local transform: translation, then rotation (unit quaternion x, y, z, w).
Eigen::Affine3d local_transform(const json& node) {
  Eigen::Affine3d local = Eigen::Affine3d::Identity();
  if (node.contains("translation"))
    local.translate(
        Eigen::Vector3d(node["translation"][0], node["translation"][1], node["translation"][2]));
  if (node.contains("rotation"))
    local.rotate(Eigen::Quaterniond(node["rotation"][3], node["rotation"][0], node["rotation"][1],
                                    node["rotation"][2]));
  return local;
}

// One JOINTS_n / WEIGHTS_n pair of the file: four joints and weights per vertex.
struct InfluenceSet {
  std::vector<std::uint16_t> joints;
  std::vector<float> weights;
};

// Every set of the file, read once.
std::vector<InfluenceSet> influence_sets(const Glb& file) {
  const json& attributes = file.gltf["meshes"][0]["primitives"][0]["attributes"];
  std::vector<InfluenceSet> sets;
  for (int set = 0; attributes.contains("JOINTS_" + std::to_string(set)); ++set)
    sets.push_back(
        {file.read<std::uint16_t>(attributes["JOINTS_" + std::to_string(set)], 5123, "VEC4", 4),
         file.read<float>(attributes["WEIGHTS_" + std::to_string(set)], 5126, "VEC4", 4)});
  return sets;
}

// Every vertex skinned as a glTF reader does: world(joint) · inverseBind(joint) blended by the
// weights of every JOINTS_n / WEIGHTS_n set.
std::vector<Eigen::Vector3d> skin_as_gltf(const Glb& file) {
  const json& gltf = file.gltf;
  const std::size_t node_count = gltf["nodes"].size();
  std::vector<std::size_t> parent(node_count, SIZE_MAX);
  for (std::size_t i = 0; i < node_count; ++i)
    for (const json& child : gltf["nodes"][i].value("children", json::array()))
      parent[child.get<std::size_t>()] = i;
  const auto world = [&](std::size_t node) {
    Eigen::Affine3d transform = Eigen::Affine3d::Identity();
    for (std::size_t at = node; at != SIZE_MAX; at = parent[at])
      transform = local_transform(gltf["nodes"][at]) * transform;
    return transform;
  };
  const json& skin = gltf["skins"][0];
  const auto inverse_binds = file.read<float>(skin["inverseBindMatrices"], 5126, "MAT4", 16);
  std::vector<Eigen::Affine3d> joint_matrices;
  for (std::size_t j = 0; j < skin["joints"].size(); ++j) {
    Eigen::Matrix4d inverse_bind;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) inverse_bind(r, c) = inverse_binds[16 * j + 4 * c + r];
    joint_matrices.push_back(world(skin["joints"][j]) * Eigen::Affine3d(inverse_bind));
  }
  const json& attributes = gltf["meshes"][0]["primitives"][0]["attributes"];
  const auto positions = file.read<float>(attributes["POSITION"], 5126, "VEC3", 3);
  std::vector<Eigen::Vector3d> out(positions.size() / 3, Eigen::Vector3d::Zero());
  for (const InfluenceSet& set : influence_sets(file))
    for (std::size_t v = 0; v < out.size(); ++v) {
      const Eigen::Vector3d rest(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
      for (std::size_t i = 4 * v; i < 4 * v + 4; ++i)
        out[v] += double{set.weights[i]} * (joint_matrices.at(set.joints[i]) * rest);
    }
  return out;
}

// Gives the bone nodes that turn about `rotation.joint` its rotation, as a reader's animation
// would; returns how many there are.
std::size_t rotate_bone_nodes(Glb& file, const JointRotation& rotation) {
  std::size_t rotated = 0;
  for (json& node : file.gltf["nodes"])
    if (node.contains("extras") && node["extras"].contains("bone") &&
        node["extras"]["joint"] == rotation.joint) {
      const Eigen::Quaterniond q(
          Eigen::AngleAxisd(rotation.angle, Eigen::Vector3d(rotation.axis.data()).normalized()));
      node["rotation"] = {q.x(), q.y(), q.z(), q.w()};
      ++rotated;
    }
  return rotated;
}

// The stick figure's skeleton at its 8 parts and its skin weights.
struct Rig {
  testing::StickFigure figure = testing::make_stick_figure();
  Skeleton skeleton;
  SkinWeights weights;
  double size = 0;

  Rig() {
    HierarchyOptions options;
    options.primitives = {PrimitiveType::Cylinder, PrimitiveType::Sphere};
    const Hierarchy hierarchy = build_hierarchy(figure.mesh, options);
    skeleton = extract_skeleton(hierarchy, cut_by_count(hierarchy, 8));
    weights = compute_skin_weights(figure.mesh, skeleton);
    for (const Vec3& p : figure.mesh.positions)
      for (const double x : p) size = std::max(size, std::abs(x));
  }
};

const Rig& rig() {
  static const Rig shared;
  return shared;
}

// The centre of the mesh's box (every vertex is a face's here), computed apart from the library.
Vec3 box_centre(const Mesh& mesh) {
  Vec3 low = mesh.positions[0], high = mesh.positions[0];
  for (const Vec3& p : mesh.positions)
    for (int i = 0; i < 3; ++i) {
      low[i] = std::min(low[i], p[i]);
      high[i] = std::max(high[i], p[i]);
    }
  return {low[0] + (high[0] - low[0]) / 2, low[1] + (high[1] - low[1]) / 2,
          low[2] + (high[2] - low[2]) / 2};
}

// The weights of vertex v in every set, as (bone, weight) pairs with a weight above zero.
std::vector<std::pair<std::uint32_t, double>> weights_of(const std::vector<InfluenceSet>& sets,
                                                         std::uint32_t v) {
  std::vector<std::pair<std::uint32_t, double>> row;
  for (const InfluenceSet& set : sets)
    for (std::size_t i = 4 * std::size_t{v}; i < 4 * std::size_t{v} + 4; ++i)
      if (set.weights[i] > 0) row.emplace_back(set.joints[i], set.weights[i]);
  std::sort(row.begin(), row.end());
  return row;
}

TEST(SkeletonGltf, TheFileHoldsTheMeshAndEveryWeightAsWritten) {
  const Rig& r = rig();
  const Mesh& mesh = r.figure.mesh;
  const Glb file(skinned_glb(mesh, r.skeleton, r.weights));
  EXPECT_EQ(file.gltf["asset"]["version"], "2.0");
  const json& primitive = file.gltf["meshes"][0]["primitives"][0];
  const auto positions = file.read<float>(primitive["attributes"]["POSITION"], 5126, "VEC3", 3);
  ASSERT_EQ(positions.size(), 3 * std::size_t{mesh.vertex_count()});
  // Relative to the centre of the bounding box, where the skeleton node stands.
  const Vec3 centre = box_centre(mesh);
  EXPECT_EQ(file.gltf["nodes"][1]["translation"].get<std::vector<double>>(),
            std::vector<double>(centre.begin(), centre.end()));
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
    for (int i = 0; i < 3; ++i)
      ASSERT_EQ(positions[3 * v + i], static_cast<float>(mesh.positions[v][i] - centre[i]));
  const auto indices = file.read<std::uint32_t>(primitive["indices"], 5125, "SCALAR", 1);
  ASSERT_EQ(indices.size(), 3 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int i = 0; i < 3; ++i) ASSERT_EQ(indices[3 * t + i], mesh.triangles[t][i]);
  const auto normals = file.read<float>(primitive["attributes"]["NORMAL"], 5126, "VEC3", 3);
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
    ASSERT_NEAR(std::hypot(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]), 1.0, 1e-6);

  // Every row as compute_skin_weights gave it, to float32 round-off, summing to 1.
  const auto sets = influence_sets(file);
  std::size_t widest = 0;
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    const auto row = weights_of(sets, v);
    const auto bones = r.weights.bones_of(v);
    const auto weights = r.weights.weights_of(v);
    widest = std::max(widest, bones.size());
    ASSERT_EQ(row.size(), bones.size()) << "vertex " << v;
    double sum = 0;
    for (std::size_t i = 0; i < row.size(); ++i) {
      EXPECT_EQ(row[i].first, bones[i]);
      EXPECT_NEAR(row[i].second, weights[i], 2e-7);
      sum += row[i].second;
    }
    ASSERT_EQ(sum, 1.0);  // exactly: a far part's joints blend without drift
  }
  EXPECT_GE(widest, 2u);
  EXPECT_TRUE(primitive["attributes"].contains("JOINTS_0"));
  EXPECT_EQ(primitive["attributes"].contains("JOINTS_1"), widest > 4);
}

TEST(SkeletonGltf, NodesFollowTheBoneTreeAndSitAtTheirPivots) {
  const Rig& r = rig();
  const Glb file(skinned_glb(r.figure.mesh, r.skeleton, r.weights));
  const json& nodes = file.gltf["nodes"];
  const BoneTree tree = bone_tree(r.skeleton);
  const std::uint32_t k = r.skeleton.cluster_count();
  std::size_t ends = 0;
  for (const Joint& joint : r.skeleton.joints) ends += joint.kind == JointKind::Virtual;
  ASSERT_EQ(nodes.size(), 2 + k + ends);
  EXPECT_EQ(file.gltf["skins"][0]["joints"].size(), k + ends);
  EXPECT_EQ(file.gltf["skins"][0]["skeleton"], 1);
  // Positions of the nodes in the rest pose: the sum of the translations down from the root.
  std::vector<Eigen::Vector3d> at(nodes.size(), Eigen::Vector3d::Zero());
  const std::function<void(std::size_t)> place = [&](std::size_t node) {
    for (const json& child : nodes[node].value("children", json::array())) {
      const std::size_t c = child;
      at[c] = at[node] + local_transform(nodes[c]).translation();
      place(c);
    }
  };
  at[1] = local_transform(nodes[1]).translation();
  place(1);
  for (std::uint32_t b = 0; b < k; ++b) {
    const json& node = nodes[2 + b];
    EXPECT_EQ(node["name"], "bone_" + std::to_string(b));
    EXPECT_EQ(node["extras"]["bone"], b);
    const Vec3 pivot = tree.parent_joint[b] == kNone
                           ? r.skeleton.bones[b].point
                           : r.skeleton.joints[tree.parent_joint[b]].position;
    EXPECT_LE((at[2 + b] - Eigen::Vector3d(pivot[0], pivot[1], pivot[2])).norm(), 1e-12 * r.size);
    if (tree.parent_joint[b] == kNone) {
      EXPECT_TRUE(node["extras"]["joint"].is_null());
    } else {
      EXPECT_EQ(node["extras"]["joint"], tree.parent_joint[b]);
      EXPECT_EQ(node["extras"]["joint_kind"],
                to_string(r.skeleton.joints[tree.parent_joint[b]].kind));
    }
  }
  for (std::size_t e = 0; e < ends; ++e) {
    const json& node = nodes[2 + k + e];
    const Vec3& position = r.skeleton.joints[node["extras"]["joint"].get<std::size_t>()].position;
    EXPECT_EQ(r.skeleton.joints[node["extras"]["joint"].get<std::size_t>()].kind,
              JointKind::Virtual);
    EXPECT_LE((at[2 + k + e] - Eigen::Vector3d(position[0], position[1], position[2])).norm(),
              1e-12 * r.size);
  }
}

TEST(SkeletonGltf, RotatingTheNodesPosesTheMeshAsDeformDoes) {
  const Rig& r = rig();
  const std::string bytes = skinned_glb(r.figure.mesh, r.skeleton, r.weights);
  Glb file(bytes);
  // The rest pose: every vertex where it was, to float32 round-off.
  const auto rest = skin_as_gltf(file);
  for (std::uint32_t v = 0; v < r.figure.mesh.vertex_count(); ++v)
    ASSERT_LE((rest[v] - Eigen::Vector3d(r.figure.mesh.positions[v].data())).norm(), 1e-6 * r.size);

  // Every sensitive joint turned, nested ones included: its bone's node takes the rotation.
  std::vector<JointRotation> pose;
  double angle = 0.3;
  for (const Joint& joint : r.skeleton.joints)
    if (joint.kind == JointKind::Sensitive) {
      pose.push_back({joint.id, {0.3, -1.0, angle}, angle});
      angle = -1.7 * angle;
    }
  ASSERT_GE(pose.size(), 4u);
  for (const JointRotation& rotation : pose) {
    ASSERT_EQ(rotate_bone_nodes(file, rotation), 1u) << "joint " << rotation.joint;
  }
  const auto posed = skin_as_gltf(file);
  const std::vector<Vec3> expected =
      skin_positions(r.figure.mesh.positions, r.weights, pose_bones(r.skeleton, pose));
  double largest = 0, moved = 0;
  for (std::uint32_t v = 0; v < r.figure.mesh.vertex_count(); ++v) {
    largest = std::max(largest, (posed[v] - Eigen::Vector3d(expected[v].data())).norm());
    moved = std::max(moved, (Eigen::Vector3d(expected[v].data()) - rest[v]).norm());
  }
  EXPECT_GT(moved, 0.5 * r.size);
  EXPECT_LE(largest, 1e-5 * r.size);
}

// A figure's weights spread over six bones at one vertex: every weight is kept in two sets, or
// the four largest, rescaled, with max_influences = 4.
TEST(SkeletonGltf, WideRowsTakeMoreSetsOrKeepTheLargestWeights) {
  const Rig& r = rig();
  SkinWeights wide = r.weights;
  const std::uint32_t v = 7, k = r.skeleton.cluster_count();
  ASSERT_GE(k, 6u);
  const std::vector<double> spread = {0.05, 0.3, 0.1, 0.25, 0.2, 0.1};
  std::vector<std::uint32_t> bones;
  std::vector<double> weights;
  for (std::uint32_t u = 0; u < wide.vertex_count(); ++u) {
    if (u == v) {
      for (std::uint32_t b = 0; b < 6; ++b) bones.push_back(b);
      weights.insert(weights.end(), spread.begin(), spread.end());
    } else {
      bones.insert(bones.end(), r.weights.bones_of(u).begin(), r.weights.bones_of(u).end());
      weights.insert(weights.end(), r.weights.weights_of(u).begin(), r.weights.weights_of(u).end());
    }
    wide.offsets[u + 1] = static_cast<std::uint32_t>(bones.size());
  }
  wide.bones = bones;
  wide.weights = weights;

  const Glb all(skinned_glb(r.figure.mesh, r.skeleton, wide));
  const json& attributes = all.gltf["meshes"][0]["primitives"][0]["attributes"];
  EXPECT_TRUE(attributes.contains("JOINTS_1"));
  EXPECT_FALSE(attributes.contains("JOINTS_2"));
  auto row = weights_of(influence_sets(all), v);
  ASSERT_EQ(row.size(), 6u);
  for (std::uint32_t b = 0; b < 6; ++b) EXPECT_NEAR(row[b].second, spread[b], 1e-7);
  // The largest four are in the first set, largest first.
  const auto first = all.read<std::uint16_t>(attributes["JOINTS_0"], 5123, "VEC4", 4);
  EXPECT_EQ(std::vector<std::uint16_t>(first.begin() + 4 * v, first.begin() + 4 * v + 4),
            (std::vector<std::uint16_t>{1, 3, 4, 2}));

  GltfOptions four;
  four.max_influences = 4;
  const Glb capped(skinned_glb(r.figure.mesh, r.skeleton, wide, four));
  EXPECT_FALSE(capped.gltf["meshes"][0]["primitives"][0]["attributes"].contains("JOINTS_1"));
  const auto capped_sets = influence_sets(capped);
  row = weights_of(capped_sets, v);
  ASSERT_EQ(row.size(), 4u);
  const double kept = 0.3 + 0.25 + 0.2 + 0.1;
  EXPECT_EQ(row[0].first, 1u);
  EXPECT_NEAR(row[0].second, 0.3 / kept, 1e-7);
  EXPECT_EQ(row[2].first, 3u);
  EXPECT_NEAR(row[2].second, 0.25 / kept, 1e-7);
  // Rows of two bones are unchanged by the cap.
  EXPECT_EQ(weights_of(capped_sets, 0), weights_of(influence_sets(all), 0));
}

// A part far from the origin, as scans in survey coordinates are (millions of units away, a
// thousand times its size): float32 positions relative to its centre keep the rest pose and
// the poses to float32 round-off of its size, not of its distance (0.25 units there).
TEST(SkeletonGltf, APartFarFromTheOriginKeepsItsPrecision) {
  const Rig& near = rig();
  const Vec3 far{3.0e6, -2.0e6, 5.0e6};
  Mesh mesh = near.figure.mesh;
  for (Vec3& p : mesh.positions)
    for (int i = 0; i < 3; ++i) p[i] += far[i];
  HierarchyOptions options;
  options.primitives = {PrimitiveType::Cylinder, PrimitiveType::Sphere};
  const Hierarchy hierarchy = build_hierarchy(mesh, options);
  const Skeleton skeleton = extract_skeleton(hierarchy, cut_by_count(hierarchy, 8));
  const SkinWeights weights = compute_skin_weights(mesh, skeleton);
  Glb file(skinned_glb(mesh, skeleton, weights));

  const auto rest = skin_as_gltf(file);
  double worst = 0;
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
    worst = std::max(worst, (rest[v] - Eigen::Vector3d(mesh.positions[v].data())).norm());
  EXPECT_LE(worst, 1e-6 * near.size);

  JointRotation elbow{kNone, {0.2, 1.0, -0.4}, 0.8};
  for (const Joint& joint : skeleton.joints)
    if (joint.kind == JointKind::Sensitive) elbow.joint = joint.id;
  ASSERT_NE(elbow.joint, kNone);
  ASSERT_EQ(rotate_bone_nodes(file, elbow), 1u);
  const auto posed = skin_as_gltf(file);
  const std::vector<Vec3> expected =
      skin_positions(mesh.positions, weights, pose_bones(skeleton, {&elbow, 1}));
  double largest = 0, moved = 0;
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    largest = std::max(largest, (posed[v] - Eigen::Vector3d(expected[v].data())).norm());
    moved = std::max(moved, (posed[v] - rest[v]).norm());
  }
  EXPECT_GT(moved, 0.1 * near.size);
  EXPECT_LE(largest, 1e-5 * near.size);
}

TEST(SkeletonGltf, AVertexOfNoTriangleFollowsTheRootBone) {
  Mesh mesh = rig().figure.mesh;
  mesh.positions.push_back({100, 0, 0});
  const Rig& r = rig();
  const SkinWeights weights = compute_skin_weights(mesh, r.skeleton);
  ASSERT_EQ(weights.bones_of(mesh.vertex_count() - 1).size(), 0u);
  const Glb file(skinned_glb(mesh, r.skeleton, weights));
  const auto row = weights_of(influence_sets(file), mesh.vertex_count() - 1);
  ASSERT_EQ(row.size(), 1u);
  EXPECT_EQ(row[0].first, r.skeleton.root_bone());
  EXPECT_EQ(row[0].second, 1.0);
}

TEST(SkeletonGltf, TheSameRigGivesTheSameBytes) {
  const Rig& r = rig();
  EXPECT_EQ(skinned_glb(r.figure.mesh, r.skeleton, r.weights),
            skinned_glb(r.figure.mesh, r.skeleton, r.weights));
}

// The file's triangles face one way whatever way the input lists them (readers cull back faces
// and shade with the normals): flipping every other triangle of the input changes no byte.
TEST(SkeletonGltf, TrianglesAreWrittenConsistentlyOriented) {
  const Rig& r = rig();
  Mesh mixed = r.figure.mesh;
  for (std::size_t t = 1; t < mixed.triangles.size(); t += 2)
    std::swap(mixed.triangles[t][1], mixed.triangles[t][2]);
  const std::string expected = skinned_glb(r.figure.mesh, r.skeleton, r.weights);
  EXPECT_EQ(skinned_glb(mixed, r.skeleton, r.weights), expected);
  // And they face outwards: the signed volume they enclose is positive.
  const Glb file(expected);
  const json& primitive = file.gltf["meshes"][0]["primitives"][0];
  const auto indices = file.read<std::uint32_t>(primitive["indices"], 5125, "SCALAR", 1);
  const Mesh& mesh = r.figure.mesh;
  double volume = 0;
  for (std::size_t i = 0; i < indices.size(); i += 3) {
    const Eigen::Vector3d a(mesh.positions[indices[i]].data()),
        b(mesh.positions[indices[i + 1]].data()), c(mesh.positions[indices[i + 2]].data());
    volume += a.dot(b.cross(c)) / 6;
  }
  EXPECT_GT(volume, 0);
}

TEST(SkeletonGltf, InconsistentInputIsRefused) {
  const Rig& r = rig();
  const auto refused = [&](const Mesh& mesh, const Skeleton& skeleton, const SkinWeights& weights,
                           const std::string& message) {
    try {
      (void)skinned_glb(mesh, skeleton, weights);
      ADD_FAILURE() << "accepted; expected: " << message;
    } catch (const InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  Mesh more = r.figure.mesh;
  more.positions.push_back({0, 0, 0});
  refused(more, r.skeleton, r.weights, "one row per vertex");
  SkinWeights bad = r.weights;
  bad.bones[0] = r.skeleton.cluster_count();
  refused(r.figure.mesh, r.skeleton, bad, "names bone");
  bad = r.weights;
  bad.weights[3] = std::nan("");
  refused(r.figure.mesh, r.skeleton, bad, "finite");
  Skeleton fewer = r.skeleton;
  fewer.face_labels.pop_back();
  refused(r.figure.mesh, fewer, r.weights, "face labels");
  refused(r.figure.mesh, Skeleton{}, r.weights, "no bone");
}

}  // namespace
}  // namespace primseg
