#include "primseg/skeleton.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <utility>

#include "no_index.hpp"
#include "primseg/error.hpp"
#include "skeleton_geometry.hpp"

namespace primseg {

std::string_view to_string(JointKind kind) {
  switch (kind) {
    case JointKind::Sensitive:
      return "sensitive";
    case JointKind::Locked:
      return "locked";
    case JointKind::Virtual:
      return "virtual";
  }
  return "unknown";
}

std::optional<JointKind> joint_kind_from_string(std::string_view name) {
  for (const JointKind kind : {JointKind::Sensitive, JointKind::Locked, JointKind::Virtual})
    if (to_string(kind) == name) return kind;
  return std::nullopt;
}

namespace {

using namespace skeleton_detail;

using detail::kNone;

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

void check_input(const Mesh& mesh, std::span<const std::uint32_t> face_labels,
                 std::span<const Primitive> primitives) {
  if (face_labels.size() != mesh.face_count())
    throw InvalidInputError("extract_skeleton: " + std::to_string(face_labels.size()) +
                            " labels for " + std::to_string(mesh.face_count()) + " faces");
  std::vector<bool> used(primitives.size(), false);
  for (const std::uint32_t label : face_labels) {
    if (label >= primitives.size())
      throw InvalidInputError("extract_skeleton: label " + std::to_string(label) +
                              " out of range (" + std::to_string(primitives.size()) + " clusters)");
    used[label] = true;
  }
  for (std::size_t c = 0; c < used.size(); ++c)
    if (!used[c])
      throw InvalidInputError("extract_skeleton: cluster " + std::to_string(c) + " has no face");
  if (mesh.face_of_triangle.size() != mesh.triangles.size())
    throw InvalidInputError("extract_skeleton: face_of_triangle does not match triangles");
  for (const Triangle& t : mesh.triangles)
    for (const std::uint32_t v : t)
      if (v >= mesh.vertex_count())
        throw InvalidInputError("extract_skeleton: vertex index out of range");
}

// Axis, point, radius and area of every cluster.
void describe_bones(const Mesh& mesh, std::span<const std::uint32_t> labels,
                    std::span<const Primitive> primitives,
                    const std::vector<std::vector<std::uint32_t>>& cluster_vertices,
                    std::vector<Bone>& bones) {
  const std::size_t k = primitives.size();
  std::vector<double> area(k, 0);
  std::vector<Vec3> first_moment(k, Vec3{0, 0, 0});
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const std::uint32_t c = labels[t];
    const Triangle& tri = mesh.triangles[t];
    const Vec3& a = mesh.positions[tri[0]];
    const Vec3& b = mesh.positions[tri[1]];
    const Vec3& d = mesh.positions[tri[2]];
    const double w = 0.5 * norm(cross(b - a, d - a));
    area[c] += w;
    first_moment[c] = first_moment[c] + (w / 3) * (a + b + d);
  }
  std::vector<Vec3> centroid(k);
  for (std::size_t c = 0; c < k; ++c) {
    if (area[c] > 0) {
      centroid[c] = (1 / area[c]) * first_moment[c];
    } else {  // zero-area cluster: the mean of its vertices
      Vec3 sum{0, 0, 0};
      for (const std::uint32_t v : cluster_vertices[c]) sum = sum + mesh.positions[v];
      centroid[c] = (1.0 / static_cast<double>(cluster_vertices[c].size())) * sum;
    }
  }
  // Second moments about the centroid (corners weighted by a third of their triangle's area),
  // for the principal direction of clusters that are not cylinders.
  std::vector<Eigen::Matrix3d> second(k, Eigen::Matrix3d::Zero());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const std::uint32_t c = labels[t];
    if (primitives[c].type == PrimitiveType::Cylinder) continue;
    const Triangle& tri = mesh.triangles[t];
    const Vec3& a = mesh.positions[tri[0]];
    const double w = 0.5 * norm(cross(mesh.positions[tri[1]] - a, mesh.positions[tri[2]] - a)) / 3;
    for (const std::uint32_t v : tri) {
      const Vec3 d = mesh.positions[v] - centroid[c];
      const Eigen::Vector3d e(d[0], d[1], d[2]);
      second[c] += w * e * e.transpose();
    }
  }
  for (std::size_t c = 0; c < k; ++c) {
    Bone& bone = bones[c];
    bone.area = area[c];
    Vec3 axis{0, 0, 0};
    if (primitives[c].type == PrimitiveType::Cylinder && norm(primitives[c].axis) > 0) {
      axis = normalized(primitives[c].axis);
    } else {
      Eigen::Matrix3d moment = second[c];
      // (Not norm(): squaring the entries, fourth powers of lengths, can underflow.)
      if (!(moment.cwiseAbs().maxCoeff() > 0)) {  // zero-area cluster: its vertices' spread
        moment.setZero();
        for (const std::uint32_t v : cluster_vertices[c]) {
          const Vec3 d = mesh.positions[v] - centroid[c];
          const Eigen::Vector3d e(d[0], d[1], d[2]);
          moment += e * e.transpose();
        }
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(moment);
      const Eigen::Vector3d largest = solver.eigenvectors().col(2);
      axis = {largest[0], largest[1], largest[2]};
      if (!(norm(axis) > 0.5)) axis = {1, 0, 0};
      axis = normalized(axis);
    }
    bone.axis = canonical_direction(axis);
    if (primitives[c].type == PrimitiveType::Cylinder) {
      bone.point =
          primitives[c].point + dot(centroid[c] - primitives[c].point, bone.axis) * bone.axis;
      bone.radius = primitives[c].radius;
    } else {
      bone.point = centroid[c];
      double sum = 0;
      for (const std::uint32_t v : cluster_vertices[c])
        sum += distance_to_line(mesh.positions[v], bone.point, bone.axis);
      bone.radius =
          cluster_vertices[c].empty() ? 0 : sum / static_cast<double>(cluster_vertices[c].size());
    }
  }
}

// Position of a virtual joint: the extent of the cluster's vertices along its axis, on the side
// away from `from` (or the given side when there is no joint to be away from).
Vec3 far_end(const Mesh& mesh, const Bone& bone, const std::vector<std::uint32_t>& vertices,
             const Vec3* from, bool high_side) {
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const std::uint32_t v : vertices) {
    const double t = dot(mesh.positions[v] - bone.point, bone.axis);
    low = std::min(low, t);
    high = std::max(high, t);
  }
  if (from) {
    const double t = dot(*from - bone.point, bone.axis);
    high_side = std::abs(high - t) >= std::abs(low - t);
  }
  return bone.point + (high_side ? high : low) * bone.axis;
}

// Each cluster's vertices (of its triangles), in increasing order.
std::vector<std::vector<std::uint32_t>> vertices_of_clusters(
    const Mesh& mesh, const std::vector<std::uint32_t>& labels, std::size_t k) {
  std::vector<std::vector<std::uint32_t>> cluster_vertices(k);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (const std::uint32_t v : mesh.triangles[t]) cluster_vertices[labels[t]].push_back(v);
  for (auto& vertices : cluster_vertices) {
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  }
  return cluster_vertices;
}

// The groups of pair boundaries that touch (share a vertex: union-find over pairs), each a joint,
// in the order of their lowest boundary vertex.
std::vector<std::vector<std::uint32_t>> touching_boundaries(
    const Mesh& mesh, const std::vector<ClusterPairBoundary>& pairs) {
  std::vector<std::uint32_t> pair_parent(pairs.size());
  std::iota(pair_parent.begin(), pair_parent.end(), 0u);
  std::vector<std::uint32_t> vertex_pair(mesh.vertex_count(), kNone);  // a pair at the vertex
  for (std::uint32_t p = 0; p < pairs.size(); ++p)
    for (const std::uint32_t v : pairs[p].vertices) {
      if (vertex_pair[v] == kNone) {
        vertex_pair[v] = p;
        continue;
      }
      const std::uint32_t a = find_root(pair_parent, vertex_pair[v]), b = find_root(pair_parent, p);
      if (a != b) pair_parent[std::max(a, b)] = std::min(a, b);
    }
  std::map<std::uint32_t, std::vector<std::uint32_t>> groups;  // root pair -> pairs
  for (std::uint32_t p = 0; p < pairs.size(); ++p) groups[find_root(pair_parent, p)].push_back(p);
  std::vector<std::pair<std::uint32_t, std::vector<std::uint32_t>>> ordered;
  for (auto& [root, members] : groups) {
    std::uint32_t lowest = kNone;
    for (const std::uint32_t p : members) lowest = std::min(lowest, pairs[p].vertices.front());
    ordered.emplace_back(lowest, std::move(members));
  }
  std::sort(ordered.begin(), ordered.end());
  std::vector<std::vector<std::uint32_t>> joints;
  joints.reserve(ordered.size());
  for (auto& [lowest, members] : ordered) joints.push_back(std::move(members));
  return joints;
}

// The joint of the touching pair boundaries `members`: at their length-weighted midpoint, between
// the bones they separate; sensitive between two bones, locked among more.
Joint boundary_joint(const Mesh& mesh, const std::vector<ClusterPairBoundary>& pairs,
                     const std::vector<std::uint32_t>& members, std::uint32_t id) {
  Joint joint;
  joint.id = id;
  double length = 0;
  Vec3 weighted{0, 0, 0}, vertex_sum{0, 0, 0};
  std::size_t vertex_count = 0;
  for (const std::uint32_t p : members) {
    length += pairs[p].length;
    weighted = weighted + pairs[p].weighted_midpoints;
    for (const std::uint32_t v : pairs[p].vertices) vertex_sum = vertex_sum + mesh.positions[v];
    vertex_count += pairs[p].vertices.size();
    joint.bones.push_back(pairs[p].first);
    joint.bones.push_back(pairs[p].second);
  }
  // Zero-length boundaries (degenerate edges only): the mean of their vertices.
  joint.position =
      length > 0 ? (1 / length) * weighted : (1.0 / static_cast<double>(vertex_count)) * vertex_sum;
  std::sort(joint.bones.begin(), joint.bones.end());
  joint.bones.erase(std::unique(joint.bones.begin(), joint.bones.end()), joint.bones.end());
  joint.kind = joint.bones.size() <= 2 ? JointKind::Sensitive : JointKind::Locked;
  return joint;
}

// Virtual joints at the free ends of bone c: both ends of a bone with no neighbour, the end away
// from its one neighbour's joint for a bone with one.
std::vector<Vec3> free_ends(const Mesh& mesh, const Skeleton& skeleton, std::size_t c,
                            const std::vector<std::uint32_t>& vertices) {
  const Bone& bone = skeleton.bones[c];
  std::vector<std::uint32_t> neighbours;
  for (const std::uint32_t j : bone.joints)
    for (const std::uint32_t b : skeleton.joints[j].bones)
      if (b != c) neighbours.push_back(b);
  std::sort(neighbours.begin(), neighbours.end());
  neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
  std::vector<Vec3> ends;
  if (neighbours.empty()) {
    ends.push_back(far_end(mesh, bone, vertices, nullptr, false));
    ends.push_back(far_end(mesh, bone, vertices, nullptr, true));
  } else if (neighbours.size() == 1) {
    const Vec3 from = skeleton.joints[bone.joints.front()].position;
    ends.push_back(far_end(mesh, bone, vertices, &from, false));
  }
  return ends;
}

}  // namespace

Skeleton extract_skeleton(const Mesh& mesh, std::span<const std::uint32_t> face_labels,
                          std::span<const Primitive> primitives) {
  check_input(mesh, face_labels, primitives);
  const std::size_t k = primitives.size();
  Skeleton skeleton;
  skeleton.face_labels.assign(face_labels.begin(), face_labels.end());
  skeleton.bones.resize(k);
  for (std::size_t c = 0; c < k; ++c) {
    skeleton.bones[c].id = static_cast<std::uint32_t>(c);
    skeleton.bones[c].cluster = static_cast<std::uint32_t>(c);
  }
  const std::vector<std::uint32_t> labels = triangle_labels(mesh, face_labels);
  const std::vector<std::vector<std::uint32_t>> cluster_vertices =
      vertices_of_clusters(mesh, labels, k);
  describe_bones(mesh, labels, primitives, cluster_vertices, skeleton.bones);

  const std::vector<ClusterPairBoundary> pairs = cluster_pair_boundaries(mesh, labels);
  for (const std::vector<std::uint32_t>& members : touching_boundaries(mesh, pairs)) {
    Joint joint =
        boundary_joint(mesh, pairs, members, static_cast<std::uint32_t>(skeleton.joints.size()));
    for (const std::uint32_t b : joint.bones) skeleton.bones[b].joints.push_back(joint.id);
    skeleton.joints.push_back(std::move(joint));
  }
  for (std::size_t c = 0; c < k; ++c)
    for (const Vec3& end : free_ends(mesh, skeleton, c, cluster_vertices[c])) {
      Joint joint;
      joint.id = static_cast<std::uint32_t>(skeleton.joints.size());
      joint.position = end;
      joint.kind = JointKind::Virtual;
      joint.bones = {static_cast<std::uint32_t>(c)};
      skeleton.bones[c].joints.push_back(joint.id);
      skeleton.joints.push_back(std::move(joint));
    }

  for (Bone& bone : skeleton.bones)
    bone.visible = !std::all_of(bone.joints.begin(), bone.joints.end(), [&](std::uint32_t j) {
      return skeleton.joints[j].kind == JointKind::Locked;
    });
  for (Joint& joint : skeleton.joints)
    joint.visible = std::any_of(joint.bones.begin(), joint.bones.end(),
                                [&](std::uint32_t b) { return skeleton.bones[b].visible; });
  return skeleton;
}

Skeleton extract_skeleton(const Hierarchy& hierarchy, const Segmentation& segmentation) {
  return extract_skeleton(hierarchy.mesh(), segmentation.labels,
                          cluster_primitives(describe_clusters(hierarchy, segmentation)));
}

}  // namespace primseg
