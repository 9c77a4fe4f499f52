#include "primseg/skinning.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <queue>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "no_index.hpp"
#include "primseg/error.hpp"
#include "skeleton_geometry.hpp"

namespace primseg {

using namespace skeleton_detail;

namespace {

using detail::kNone;

double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// Vertex adjacency along the edges of triangles, each neighbour with the triangle's cluster.
struct LabelledNeighbour {
  std::uint32_t vertex, cluster;
};

std::vector<std::vector<LabelledNeighbour>> labelled_adjacency(
    const Mesh& mesh, std::span<const std::uint32_t> labels) {
  std::vector<std::vector<LabelledNeighbour>> adjacency(mesh.vertex_count());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = tri[e], b = tri[(e + 1) % 3];
      if (a == b) continue;
      adjacency[a].push_back({b, labels[t]});
      adjacency[b].push_back({a, labels[t]});
    }
  }
  return adjacency;
}

// Triangles of each cluster at each vertex: per vertex, (cluster, count) rows sorted by cluster.
using IncidentClusters = std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>>;

IncidentClusters incident_clusters(const Mesh& mesh, std::span<const std::uint32_t> labels) {
  IncidentClusters incident(mesh.vertex_count());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (const std::uint32_t v : mesh.triangles[t]) {
      auto& row = incident[v];
      auto it =
          std::find_if(row.begin(), row.end(), [&](const auto& e) { return e.first == labels[t]; });
      if (it == row.end())
        row.emplace_back(labels[t], 1);
      else
        ++it->second;
    }
  for (auto& row : incident) std::sort(row.begin(), row.end());
  return incident;
}

// (vertex, own cluster) -> neighbour cluster -> the weight the vertex gives that neighbour's
// bone: half at their boundary, falling smoothly to 0 at `band` × the own bone's radius inside.
using BoundaryBlend =
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::map<std::uint32_t, double>>;

// Each side of each boundary between two clusters: the bounded Dijkstra distance inside the own
// cluster from the boundary, and the weight it gives the other side.
BoundaryBlend boundary_blend(const Mesh& mesh, const Skeleton& skeleton,
                             std::span<const std::uint32_t> labels,
                             const std::vector<std::vector<LabelledNeighbour>>& adjacency,
                             double band_in_radii) {
  BoundaryBlend alpha;
  std::vector<double> distance(mesh.vertex_count(), std::numeric_limits<double>::infinity());
  std::vector<std::uint32_t> touched;
  using Item = std::pair<double, std::uint32_t>;
  for (const ClusterPairBoundary& boundary : cluster_pair_boundaries(mesh, labels)) {
    for (const auto& [own, other] :
         {std::pair{boundary.first, boundary.second}, std::pair{boundary.second, boundary.first}}) {
      const double band = band_in_radii * skeleton.bones[own].radius;
      std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
      for (const std::uint32_t v : boundary.vertices) {
        distance[v] = 0;
        touched.push_back(v);
        queue.emplace(0.0, v);
      }
      while (!queue.empty()) {
        const auto [d, v] = queue.top();
        queue.pop();
        if (d > distance[v]) continue;
        alpha[{v, own}][other] = band > 0 ? 0.5 * (1 - smoothstep(d / band)) : 0.5;
        for (const LabelledNeighbour& n : adjacency[v]) {
          if (n.cluster != own) continue;
          const double next = d + norm(mesh.positions[n.vertex] - mesh.positions[v]);
          if (next < band && next < distance[n.vertex]) {
            if (distance[n.vertex] == std::numeric_limits<double>::infinity())
              touched.push_back(n.vertex);
            distance[n.vertex] = next;
            queue.emplace(next, n.vertex);
          }
        }
      }
      for (const std::uint32_t v : touched) distance[v] = std::numeric_limits<double>::infinity();
      touched.clear();
    }
  }
  return alpha;
}

// Each vertex's weights: each incident cluster's share of its triangles, of which the cluster's
// own bone keeps what the blend does not give its neighbours' bones; normalised, zeros dropped.
SkinWeights blended_weights(const IncidentClusters& incident, const BoundaryBlend& alpha) {
  SkinWeights result;
  result.offsets.reserve(incident.size() + 1);
  std::map<std::uint32_t, double> row;
  for (std::uint32_t v = 0; v < incident.size(); ++v) {
    row.clear();
    double total_triangles = 0;
    for (const auto& [cluster, count] : incident[v]) total_triangles += count;
    for (const auto& [cluster, count] : incident[v]) {
      const double share = count / total_triangles;
      double given = 0;
      const auto found = alpha.find({v, cluster});
      if (found != alpha.end())
        for (const auto& [other, a] : found->second) given += a;
      // Near several boundaries at once (a short bone): keep the own weight non-negative.
      const double scale = given > 1 ? 1 / given : 1;
      if (found != alpha.end())
        for (const auto& [other, a] : found->second) row[other] += share * scale * a;
      row[cluster] += share * (1 - scale * given);
    }
    double sum = 0;
    for (const auto& [bone, w] : row) sum += w;
    for (const auto& [bone, w] : row)
      if (w > 0) {
        result.bones.push_back(bone);
        result.weights.push_back(w / sum);
      }
    result.offsets.push_back(static_cast<std::uint32_t>(result.bones.size()));
  }
  return result;
}

}  // namespace

SkinWeights compute_skin_weights(const Mesh& mesh, const Skeleton& skeleton,
                                 const SkinningOptions& options) {
  if (!(std::isfinite(options.band) && options.band >= 0))
    throw InvalidInputError("compute_skin_weights: band must be finite and >= 0");
  skeleton_detail::check_face_labels(mesh, skeleton, "compute_skin_weights");
  for (const Triangle& tri : mesh.triangles)
    for (const std::uint32_t v : tri)
      if (v >= mesh.vertex_count())
        throw InvalidInputError("compute_skin_weights: vertex index out of range");

  const std::vector<std::uint32_t> labels = triangle_labels(mesh, skeleton.face_labels);
  return blended_weights(
      incident_clusters(mesh, labels),
      boundary_blend(mesh, skeleton, labels, labelled_adjacency(mesh, labels), options.band));
}

Vec3 RigidTransform::apply(const Vec3& x) const {
  Vec3 y = translation;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) y[i] += rotation[i][j] * x[j];
  return y;
}

RigidTransform RigidTransform::operator*(const RigidTransform& other) const {
  RigidTransform result;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double sum = 0;
      for (int m = 0; m < 3; ++m) sum += rotation[i][m] * other.rotation[m][j];
      result.rotation[i][j] = sum;
    }
  result.translation = apply(other.translation);
  return result;
}

RigidTransform RigidTransform::rotation_about(const Vec3& centre, const Vec3& axis, double angle) {
  const Vec3 u = normalized(axis);
  const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
  RigidTransform result;
  // Rodrigues' formula.
  result.rotation = {
      {{t * u[0] * u[0] + c, t * u[0] * u[1] - s * u[2], t * u[0] * u[2] + s * u[1]},
       {t * u[0] * u[1] + s * u[2], t * u[1] * u[1] + c, t * u[1] * u[2] - s * u[0]},
       {t * u[0] * u[2] - s * u[1], t * u[1] * u[2] + s * u[0], t * u[2] * u[2] + c}}};
  // Fixes the centre: x -> R (x - centre) + centre.
  Vec3 rotated_centre{0, 0, 0};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rotated_centre[i] += result.rotation[i][j] * centre[j];
  result.translation = centre - rotated_centre;
  return result;
}

BoneTree bone_tree(const Skeleton& skeleton) {
  const std::size_t k = skeleton.bones.size();
  BoneTree tree;
  tree.parent_joint.assign(k, kNone);
  tree.parent_bone.assign(k, kNone);
  std::vector<bool> reached(k, false);
  // The root bone first, then any bone not yet reached (other components), in id order.
  std::vector<std::uint32_t> starts;
  if (k > 0) starts.push_back(skeleton.root_bone());
  for (std::uint32_t b = 0; b < k; ++b) starts.push_back(b);
  for (const std::uint32_t start : starts) {
    if (reached[start]) continue;
    reached[start] = true;
    std::size_t head = tree.order.size();
    tree.order.push_back(start);
    while (head < tree.order.size()) {
      const std::uint32_t bone = tree.order[head++];
      for (const std::uint32_t j : skeleton.bones[bone].joints)
        for (const std::uint32_t next : skeleton.joints[j].bones) {
          if (reached[next]) continue;
          reached[next] = true;
          tree.parent_joint[next] = j;
          tree.parent_bone[next] = bone;
          tree.order.push_back(next);
        }
    }
  }
  return tree;
}

namespace {

// The bone that hangs from a sensitive joint in the tree; throws when there is none.
std::uint32_t child_of_joint(const Skeleton& skeleton, const BoneTree& tree, std::uint32_t joint) {
  if (joint >= skeleton.joints.size())
    throw InvalidInputError("joint " + std::to_string(joint) + " does not exist (" +
                            std::to_string(skeleton.joints.size()) + " joints)");
  const Joint& j = skeleton.joints[joint];
  if (j.kind != JointKind::Sensitive) {
    // Name the ones that do, so that the message says what to write instead.
    std::string sensitive;
    std::size_t count = 0;
    for (std::size_t i = 0; i < skeleton.joints.size(); ++i)
      if (skeleton.joints[i].kind == JointKind::Sensitive && count++ < 12)
        sensitive += (sensitive.empty() ? "" : ", ") + std::to_string(i);
    if (count > 12) sensitive += ", ... (" + std::to_string(count) + " in all)";
    throw InvalidInputError("joint " + std::to_string(joint) + " is " +
                            std::string(to_string(j.kind)) + ": only sensitive joints rotate (" +
                            (count ? "this skeleton's: " + sensitive : "this skeleton has none") +
                            ")");
  }
  for (const std::uint32_t b : j.bones)
    if (tree.parent_joint[b] == joint) return b;
  throw InvalidInputError("joint " + std::to_string(joint) +
                          " closes a cycle of the skeleton: it cannot rotate");
}

}  // namespace

std::vector<std::uint32_t> bones_beyond(const Skeleton& skeleton, std::uint32_t joint) {
  const BoneTree tree = bone_tree(skeleton);
  const std::uint32_t child = child_of_joint(skeleton, tree, joint);
  std::vector<bool> moving(skeleton.bones.size(), false);
  moving[child] = true;
  for (const std::uint32_t b : tree.order)  // parents come before children
    if (tree.parent_bone[b] != kNone && moving[tree.parent_bone[b]]) moving[b] = true;
  std::vector<std::uint32_t> result;
  for (std::uint32_t b = 0; b < moving.size(); ++b)
    if (moving[b]) result.push_back(b);
  return result;
}

std::vector<RigidTransform> pose_bones(const Skeleton& skeleton,
                                       std::span<const JointRotation> pose) {
  const BoneTree tree = bone_tree(skeleton);
  std::vector<RigidTransform> local(skeleton.bones.size());  // rotation at the parent joint
  std::vector<bool> posed(skeleton.joints.size(), false);
  for (const JointRotation& rotation : pose) {
    const std::uint32_t child = child_of_joint(skeleton, tree, rotation.joint);
    if (posed[rotation.joint])
      throw InvalidInputError("joint " + std::to_string(rotation.joint) + " is rotated twice");
    posed[rotation.joint] = true;
    // Of any length: scaled to its largest component first, so that its norm neither overflows
    // nor underflows.
    const double largest = std::max(
        {std::abs(rotation.axis[0]), std::abs(rotation.axis[1]), std::abs(rotation.axis[2])});
    if (!(std::isfinite(largest) && largest > 0) || !std::isfinite(rotation.angle))
      throw InvalidInputError("joint " + std::to_string(rotation.joint) +
                              ": the axis must be finite and non-zero, the angle finite");
    const Vec3 axis{rotation.axis[0] / largest, rotation.axis[1] / largest,
                    rotation.axis[2] / largest};
    local[child] = RigidTransform::rotation_about(skeleton.joints[rotation.joint].position, axis,
                                                  rotation.angle);
  }
  std::vector<RigidTransform> world(skeleton.bones.size());
  for (const std::uint32_t b : tree.order)
    world[b] = tree.parent_bone[b] == kNone ? local[b] : world[tree.parent_bone[b]] * local[b];
  return world;
}

std::vector<Vec3> skin_positions(std::span<const Vec3> rest, const SkinWeights& weights,
                                 std::span<const RigidTransform> bone_transforms) {
  if (weights.vertex_count() != rest.size())
    throw InvalidInputError("skin_positions: " + std::to_string(weights.vertex_count()) +
                            " weight rows for " + std::to_string(rest.size()) + " vertices");
  for (const std::uint32_t b : weights.bones)
    if (b >= bone_transforms.size())
      throw InvalidInputError("skin_positions: bone " + std::to_string(b) + " has no transform");
  std::vector<Vec3> result(rest.size());
  for (std::uint32_t v = 0; v < rest.size(); ++v) {
    const auto bones = weights.bones_of(v);
    if (bones.empty()) {
      result[v] = rest[v];
      continue;
    }
    // A vertex whose bones all move alike moves exactly rigidly (no rounding from the blend):
    // parts of the mesh that a pose does not reach stay bit for bit where they were.
    const RigidTransform& first = bone_transforms[bones[0]];
    if (std::all_of(bones.begin() + 1, bones.end(), [&](std::uint32_t b) {
          return bone_transforms[b].rotation == first.rotation &&
                 bone_transforms[b].translation == first.translation;
        })) {
      result[v] = first.apply(rest[v]);
      continue;
    }
    const auto w = weights.weights_of(v);
    Vec3 sum{0, 0, 0};
    for (std::size_t i = 0; i < bones.size(); ++i)
      sum = sum + w[i] * bone_transforms[bones[i]].apply(rest[v]);
    result[v] = sum;
  }
  return result;
}

std::vector<Vec3> posed_joint_positions(const Skeleton& skeleton,
                                        std::span<const RigidTransform> bone_transforms) {
  const BoneTree tree = bone_tree(skeleton);
  std::vector<std::uint32_t> depth_rank(skeleton.bones.size());
  for (std::uint32_t i = 0; i < tree.order.size(); ++i) depth_rank[tree.order[i]] = i;
  std::vector<Vec3> result(skeleton.joints.size());
  for (const Joint& joint : skeleton.joints) {
    std::uint32_t carrier = joint.bones.front();
    for (const std::uint32_t b : joint.bones)
      if (depth_rank[b] < depth_rank[carrier]) carrier = b;
    result[joint.id] = bone_transforms[carrier].apply(joint.position);
  }
  return result;
}

Mesh deform(const Mesh& mesh, const Skeleton& skeleton, std::span<const JointRotation> pose,
            const SkinningOptions& options) {
  const SkinWeights weights = compute_skin_weights(mesh, skeleton, options);
  Mesh result = mesh;
  result.positions = skin_positions(mesh.positions, weights, pose_bones(skeleton, pose));
  return result;
}

}  // namespace primseg
