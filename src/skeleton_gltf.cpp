#include "primseg/skeleton_gltf.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "json_document.hpp"
#include "no_index.hpp"
#include "primseg/dual_graph.hpp"
#include "primseg/error.hpp"
#include "shape_generator/vector_math.hpp"
#include "skeleton_geometry.hpp"

namespace primseg {
namespace {

using detail::vec3_json;
using namespace shape_detail;  // Vec3 -, cross, norm
using nlohmann::json;

static_assert(std::endian::native == std::endian::little, "GLB is little-endian");

using detail::kNone;
constexpr std::size_t kInfluencesPerSet = 4;
constexpr std::size_t kMaxSkinJoints = std::size_t{std::numeric_limits<std::uint16_t>::max()} + 1;
// glTF's enumerations.
constexpr int kFloat = 5126, kUnsignedShort = 5123, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963, kTriangles = 4;
constexpr std::uint32_t kGlbMagic = 0x46546C67, kGlbVersion = 2;          // "glTF"
constexpr std::uint32_t kJsonChunk = 0x4E4F534A, kBinChunk = 0x004E4942;  // "JSON", "BIN\0"

// Checks what skinned_glb() relies on, for weights that did not come from compute_skin_weights.
void check_inputs(const Mesh& mesh, const Skeleton& skeleton, const SkinWeights& weights) {
  const std::size_t k = skeleton.bones.size();
  if (k == 0) throw InvalidInputError("glTF skin: the skeleton has no bone");
  skeleton_detail::check_face_labels(mesh, skeleton, "glTF skin");
  if (weights.offsets.size() != std::size_t{mesh.vertex_count()} + 1 ||
      weights.offsets.front() != 0 || weights.offsets.back() != weights.bones.size() ||
      weights.bones.size() != weights.weights.size())
    throw InvalidInputError("glTF skin: the skin weights do not have one row per vertex (" +
                            std::to_string(mesh.vertex_count()) + ")");
  for (std::uint32_t v = 0; v < weights.vertex_count(); ++v)
    if (weights.offsets[v] > weights.offsets[v + 1])
      throw InvalidInputError("glTF skin: the skin weights' row offsets decrease at vertex " +
                              std::to_string(v));
  for (std::size_t i = 0; i < weights.bones.size(); ++i) {
    if (weights.bones[i] >= k)
      throw InvalidInputError("glTF skin: a skin weight names bone " +
                              std::to_string(weights.bones[i]) + " of " + std::to_string(k));
    if (!(std::isfinite(weights.weights[i]) && weights.weights[i] >= 0))
      throw InvalidInputError("glTF skin: skin weights must be finite and >= 0");
  }
  for (const Joint& joint : skeleton.joints)
    for (const std::uint32_t b : joint.bones)
      if (b >= k) throw InvalidInputError("glTF skin: a joint names a bone that does not exist");
  for (const Bone& bone : skeleton.bones)
    for (const std::uint32_t j : bone.joints)
      if (j >= skeleton.joints.size())
        throw InvalidInputError("glTF skin: a bone names a joint that does not exist");
}

// One JOINTS_n / WEIGHTS_n pair: four influences per vertex, shape (4n) each.
struct InfluenceSet {
  std::vector<std::uint16_t> joints;
  std::vector<float> weights;
};

// Each vertex's influences, largest weight first, in float32 rows summing to exactly 1, spread
// over as many sets of four as the widest row needs.
std::vector<InfluenceSet> influence_sets(const SkinWeights& skin, std::uint32_t root_bone,
                                         std::uint32_t max_influences) {
  const std::uint32_t n = skin.vertex_count();
  std::size_t widest = 1;  // an empty row follows the root bone
  for (std::uint32_t v = 0; v < n; ++v)
    widest = std::max<std::size_t>(widest, skin.offsets[v + 1] - skin.offsets[v]);
  if (max_influences > 0) widest = std::min<std::size_t>(widest, max_influences);
  std::vector<InfluenceSet> sets((widest + kInfluencesPerSet - 1) / kInfluencesPerSet);
  for (InfluenceSet& set : sets) {
    set.joints.assign(kInfluencesPerSet * n, 0);
    set.weights.assign(kInfluencesPerSet * n, 0.0f);
  }
  std::vector<std::pair<double, std::uint32_t>> row;
  for (std::size_t v = 0; v < n; ++v) {
    row.clear();
    const auto bones = skin.bones_of(static_cast<std::uint32_t>(v));
    const auto weights = skin.weights_of(static_cast<std::uint32_t>(v));
    for (std::size_t i = 0; i < bones.size(); ++i)
      if (weights[i] > 0) row.emplace_back(weights[i], bones[i]);
    // Largest first, ties by bone id: set 0 holds what matters most, deterministically.
    std::sort(row.begin(), row.end(), [](const auto& a, const auto& b) {
      return a.first > b.first || (a.first == b.first && a.second < b.second);
    });
    if (row.size() > widest) row.resize(widest);
    double total = 0;
    for (const auto& [weight, bone] : row) total += weight;
    if (row.empty() || !(total > 0)) {
      row.assign(1, {1.0, root_bone});
      total = 1;
    }
    // Rows that sum to exactly 1: the weights after the largest are rounded to multiples of
    // 2^-24 (dropped if that makes them 0), which float32 holds exactly below 1, and so does the
    // rest, which the largest takes. A reader blends the joints' translations with weights
    // summing to 1 then, not to 1 ± 6e-8, which would move a vertex by that fraction of its
    // joints' distance from the origin.
    double rest = 1;
    for (std::size_t i = 1; i < row.size(); ++i) {
      row[i].first = std::ldexp(std::round(std::ldexp(row[i].first / total, 24)), -24);
      rest -= row[i].first;
    }
    row[0].first = rest;
    std::erase_if(row, [](const auto& influence) { return influence.first == 0; });
    for (std::size_t i = 0; i < row.size(); ++i) {
      InfluenceSet& set = sets[i / kInfluencesPerSet];
      const std::size_t at = kInfluencesPerSet * v + i % kInfluencesPerSet;
      set.joints[at] = static_cast<std::uint16_t>(row[i].second);
      set.weights[at] = static_cast<float>(row[i].first);
    }
  }
  return sets;
}

// The triangles consistently oriented (outward on a closed part), as the dual graph orients them,
// whatever way the file lists them: glTF readers cull back faces and shade with the normals.
std::vector<Triangle> oriented_triangles(const Mesh& mesh) {
  std::vector<Triangle> triangles = mesh.triangles;
  const DualGraph graph(mesh, VertexWeights::Area);
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    if (graph.flipped(t)) std::swap(triangles[t][1], triangles[t][2]);
  return triangles;
}

// Area-weighted vertex normals (unit); (0, 0, 1) where the triangles around a vertex have no area.
std::vector<std::array<float, 3>> vertex_normals(const Mesh& mesh,
                                                 std::span<const Triangle> triangles) {
  const std::vector<Vec3> sums = area_weighted_normal_sums(mesh.positions, triangles);
  std::vector<std::array<float, 3>> normals(sums.size(), {0.0f, 0.0f, 1.0f});
  for (std::size_t v = 0; v < sums.size(); ++v) {
    const double length = norm(sums[v]);
    if (length > 0 && std::isfinite(length))
      for (int i = 0; i < 3; ++i) normals[v][i] = static_cast<float>(sums[v][i] / length);
  }
  return normals;
}

// The binary chunk, its views and accessors, built side by side.
class BufferBuilder {
 public:
  // Appends `data` (`count` elements of the accessor's `type`) as a view and its accessor; returns
  // the accessor's index.
  template <class T>
  std::size_t add(const std::vector<T>& data, std::size_t count, const char* type,
                  int component_type, std::optional<int> target,
                  const json& extra = json::object()) {
    const std::size_t offset = bin_.size();
    const std::size_t bytes = data.size() * sizeof(T);
    bin_.resize(offset + (bytes + 3) / 4 * 4, '\0');
    if (bytes > 0) std::memcpy(bin_.data() + offset, data.data(), bytes);
    json view{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
    if (target) view["target"] = *target;
    views_.push_back(std::move(view));
    json accessor{{"bufferView", views_.size() - 1},
                  {"componentType", component_type},
                  {"count", count},
                  {"type", type}};
    accessor.update(extra);
    accessors_.push_back(std::move(accessor));
    return accessors_.size() - 1;
  }

  void finish(json& gltf, std::string& bin) {
    gltf["buffers"] = json::array({{{"byteLength", bin_.size()}}});
    gltf["bufferViews"] = std::move(views_);
    gltf["accessors"] = std::move(accessors_);
    bin = std::move(bin_);
  }

 private:
  std::string bin_;
  json views_ = json::array(), accessors_ = json::array();
};

void append_u32(std::string& out, std::uint32_t value) {
  char bytes[4];
  std::memcpy(bytes, &value, 4);
  out.append(bytes, 4);
}

std::string glb(const json& gltf, const std::string& bin) {
  std::string text = gltf.dump();
  text.resize((text.size() + 3) / 4 * 4, ' ');  // the JSON chunk is padded with spaces
  const std::size_t total = 12 + 8 + text.size() + 8 + bin.size();
  if (total > std::numeric_limits<std::uint32_t>::max())
    throw InvalidInputError("glTF skin: the mesh is too large for a GLB file (4 GB)");
  std::string out;
  out.reserve(total);
  append_u32(out, kGlbMagic);
  append_u32(out, kGlbVersion);
  append_u32(out, static_cast<std::uint32_t>(total));
  append_u32(out, static_cast<std::uint32_t>(text.size()));
  append_u32(out, kJsonChunk);
  out += text;
  append_u32(out, static_cast<std::uint32_t>(bin.size()));
  append_u32(out, kBinChunk);
  out += bin;
  return out;
}

// The virtual joints that end a single bone (a limb's tip), in id order: nodes of the skin
// beyond the bones, so that a viewer draws the last bone's length.
std::vector<std::uint32_t> end_joints(const Skeleton& skeleton) {
  std::vector<std::uint32_t> ends;
  for (const Joint& joint : skeleton.joints)
    if (joint.kind == JointKind::Virtual && joint.bones.size() == 1) ends.push_back(joint.id);
  const std::size_t k = skeleton.cluster_count();
  if (k + ends.size() > kMaxSkinJoints)
    throw InvalidInputError("glTF skin: " + std::to_string(k) + " bones and " +
                            std::to_string(ends.size()) +
                            " end joints are more than a glTF skin's 16-bit joint indices hold");
  return ends;
}

// The point each bone turns about: the joint it hangs from, or its own axis point at a root.
std::vector<Vec3> bone_pivots(const Skeleton& skeleton, const BoneTree& tree) {
  std::vector<Vec3> pivots(skeleton.cluster_count());
  for (std::uint32_t b = 0; b < pivots.size(); ++b)
    pivots[b] = tree.parent_joint[b] == kNone ? skeleton.bones[b].point
                                              : skeleton.joints[tree.parent_joint[b]].position;
  return pivots;
}

// The mesh primitive's attributes (positions relative to `origin`, normals, joints and weights
// of each influence set) appended to `buffer`, by attribute name.
json add_vertex_attributes(BufferBuilder& buffer, const Mesh& mesh, const Vec3& origin,
                           const std::vector<Triangle>& triangles,
                           const std::vector<InfluenceSet>& sets) {
  const std::uint32_t n = mesh.vertex_count();
  std::vector<float> positions(3 * std::size_t{n});
  std::array<float, 3> low{}, high{};
  for (std::size_t v = 0; v < n; ++v)
    for (std::size_t i = 0; i < 3; ++i) {
      const float x = static_cast<float>(mesh.positions[v][i] - origin[i]);
      positions[3 * v + i] = x;
      low[i] = v == 0 ? x : std::min(low[i], x);
      high[i] = v == 0 ? x : std::max(high[i], x);
    }
  json attributes;
  attributes["POSITION"] = buffer.add(positions, n, "VEC3", kFloat, kArrayBuffer,
                                      {{"min", json::array({low[0], low[1], low[2]})},
                                       {"max", json::array({high[0], high[1], high[2]})}});
  attributes["NORMAL"] =
      buffer.add(vertex_normals(mesh, triangles), n, "VEC3", kFloat, kArrayBuffer);
  for (std::size_t set = 0; set < sets.size(); ++set) {
    // (Appended, not "_" + to_string(): g++ 12 warns falsely on that, -Wrestrict.)
    std::string joints_name = "JOINTS_", weights_name = "WEIGHTS_";
    joints_name += std::to_string(set);
    weights_name += std::to_string(set);
    attributes[joints_name] = buffer.add(sets[set].joints, n, "VEC4", kUnsignedShort, kArrayBuffer);
    attributes[weights_name] = buffer.add(sets[set].weights, n, "VEC4", kFloat, kArrayBuffer);
  }
  return attributes;
}

// The inverse bind matrices (column-major) of the bones' pivots, then of the end joints: the
// rest pose has every node unrotated, so each one only moves its joint's rest position (relative
// to `origin`, as the positions are) to the origin. Returns the accessor's index.
std::size_t add_inverse_binds(BufferBuilder& buffer, const Skeleton& skeleton,
                              const std::vector<Vec3>& pivots,
                              const std::vector<std::uint32_t>& ends, const Vec3& origin) {
  std::vector<float> inverse_binds;
  inverse_binds.reserve(16 * (pivots.size() + ends.size()));
  const auto add_inverse_bind = [&inverse_binds](const Vec3& at) {
    const float matrix[16] = {1,
                              0,
                              0,
                              0,
                              0,
                              1,
                              0,
                              0,
                              0,
                              0,
                              1,
                              0,
                              static_cast<float>(-at[0]),
                              static_cast<float>(-at[1]),
                              static_cast<float>(-at[2]),
                              1};
    inverse_binds.insert(inverse_binds.end(), matrix, matrix + 16);
  };
  for (const Vec3& pivot : pivots) add_inverse_bind(pivot - origin);
  for (const std::uint32_t j : ends) add_inverse_bind(skeleton.joints[j].position - origin);
  return buffer.add(inverse_binds, pivots.size() + ends.size(), "MAT4", kFloat, std::nullopt);
}

constexpr std::size_t kFirstBoneNode = 2;

// The scene's nodes: the mesh, the skeleton at `origin`, one node per bone at its pivot
// (relative to its parent's), then one per end joint, children in node order.
json skeleton_nodes(const Skeleton& skeleton, const BoneTree& tree, const std::vector<Vec3>& pivots,
                    const std::vector<std::uint32_t>& ends, const Vec3& origin) {
  const std::uint32_t k = skeleton.cluster_count();
  json nodes = json::array();
  nodes.push_back({{"name", "mesh"}, {"mesh", 0}, {"skin", 0}});
  nodes.push_back(
      {{"name", "skeleton"}, {"translation", vec3_json(origin)}, {"children", json::array()}});
  for (std::uint32_t b = 0; b < k; ++b) {
    const std::uint32_t parent = tree.parent_bone[b], joint = tree.parent_joint[b];
    json extras{{"bone", b}};
    extras["joint"] = joint == kNone ? json(nullptr) : json(joint);
    extras["joint_kind"] =
        joint == kNone ? json(nullptr) : json(to_string(skeleton.joints[joint].kind));
    nodes.push_back({{"name", "bone_" + std::to_string(b)},
                     {"translation",
                      vec3_json(parent == kNone ? pivots[b] - origin : pivots[b] - pivots[parent])},
                     {"extras", std::move(extras)}});
    if (parent == kNone) nodes[1]["children"].push_back(kFirstBoneNode + b);
  }
  for (const std::uint32_t end : ends) {
    const Joint& joint = skeleton.joints[end];
    const std::uint32_t bone = joint.bones[0];
    nodes.push_back({{"name", "end_" + std::to_string(joint.id)},
                     {"translation", vec3_json(joint.position - pivots[bone])},
                     {"extras", {{"joint", joint.id}, {"joint_kind", to_string(joint.kind)}}}});
  }
  // Children in node order, so that the file does not depend on the order they were found in.
  for (std::uint32_t b = 0; b < k; ++b)
    if (tree.parent_bone[b] != kNone)
      nodes[kFirstBoneNode + tree.parent_bone[b]]["children"].push_back(kFirstBoneNode + b);
  for (std::size_t e = 0; e < ends.size(); ++e)
    nodes[kFirstBoneNode + skeleton.joints[ends[e]].bones[0]]["children"].push_back(kFirstBoneNode +
                                                                                    k + e);
  return nodes;
}

}  // namespace

std::string skinned_glb(const Mesh& mesh, const Skeleton& skeleton, const SkinWeights& weights,
                        const GltfOptions& options) {
  check_inputs(mesh, skeleton, weights);
  const std::vector<std::uint32_t> ends = end_joints(skeleton);
  const std::size_t skin_joints = std::size_t{skeleton.cluster_count()} + ends.size();
  const BoneTree tree = bone_tree(skeleton);
  const std::vector<Vec3> pivots = bone_pivots(skeleton, tree);
  // Positions and pivots are written relative to the centre of the bounding box, where the
  // skeleton node stands: float32 then holds a part far from the origin (a scan in survey
  // coordinates) as finely as one at it.
  const Vec3 origin = bounding_box_centre(mesh);

  BufferBuilder buffer;
  const std::vector<Triangle> triangles = oriented_triangles(mesh);
  const json attributes =
      add_vertex_attributes(buffer, mesh, origin, triangles,
                            influence_sets(weights, skeleton.root_bone(), options.max_influences));
  std::vector<std::uint32_t> indices;
  indices.reserve(3 * mesh.triangles.size());
  for (const Triangle& t : triangles) indices.insert(indices.end(), t.begin(), t.end());
  const std::size_t index_accessor =
      buffer.add(indices, indices.size(), "SCALAR", kUnsignedInt, kElementArrayBuffer);
  const std::size_t inverse_bind_accessor =
      add_inverse_binds(buffer, skeleton, pivots, ends, origin);

  json skin_joint_nodes = json::array();
  for (std::size_t i = 0; i < skin_joints; ++i) skin_joint_nodes.push_back(kFirstBoneNode + i);
  json gltf;
  gltf["asset"] = {{"version", "2.0"}, {"generator", "primseg"}};
  gltf["scene"] = 0;
  gltf["scenes"] = json::array({{{"nodes", json::array({0, 1})}}});
  gltf["nodes"] = skeleton_nodes(skeleton, tree, pivots, ends, origin);
  gltf["meshes"] = json::array({{{"name", "mesh"},
                                 {"primitives", json::array({{{"attributes", attributes},
                                                              {"indices", index_accessor},
                                                              {"mode", kTriangles}}})}}});
  gltf["skins"] = json::array({{{"joints", std::move(skin_joint_nodes)},
                                {"inverseBindMatrices", inverse_bind_accessor},
                                {"skeleton", 1}}});
  std::string bin;
  buffer.finish(gltf, bin);
  return glb(gltf, bin);
}

}  // namespace primseg
