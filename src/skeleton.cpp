#include "primseg/skeleton.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <tuple>
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

std::string_view to_string(JointRule rule) {
  return rule == JointRule::Limbs ? "limbs" : "paper";
}

std::optional<JointRule> joint_rule_from_string(std::string_view name) {
  for (const JointRule rule : {JointRule::Paper, JointRule::Limbs})
    if (to_string(rule) == name) return rule;
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

// The cluster on the other side of a pair boundary from c.
std::uint32_t across(const ClusterPairBoundary& pair, std::uint32_t c) {
  return pair.first == c ? pair.second : pair.first;
}

// A limb of JointRule::Limbs: a cluster that its attachment loop (some of its pair boundaries)
// frees, with everything beyond its other loops, from the root bone's side.
struct Limb {
  std::uint32_t cluster = 0;
  std::vector<std::uint32_t> loop;  ///< pairs, increasing
  double protrusion = 0;            ///< farthest own vertex from the loop's plane / loop radius
};

// The pair boundaries `subset` (increasing) grouped by touch: two share a vertex, directly or
// through others of the subset (union-find). Each group is increasing, and the groups are in the
// order of their first pair. A joint of the paper's rule is such a group of all the pairs; a loop
// of a cluster, one of the cluster's own pairs.
std::vector<std::vector<std::uint32_t>> touching_groups(
    const std::vector<ClusterPairBoundary>& pairs, const std::vector<std::uint32_t>& subset) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> vertex_of;  // (vertex, index in subset)
  for (std::uint32_t i = 0; i < subset.size(); ++i)
    for (const std::uint32_t v : pairs[subset[i]].vertices) vertex_of.emplace_back(v, i);
  std::sort(vertex_of.begin(), vertex_of.end());
  std::vector<std::uint32_t> parent(subset.size());
  std::iota(parent.begin(), parent.end(), 0u);
  for (std::size_t i = 1; i < vertex_of.size(); ++i)
    if (vertex_of[i].first == vertex_of[i - 1].first) {
      const std::uint32_t a = find_root(parent, vertex_of[i].second);
      const std::uint32_t b = find_root(parent, vertex_of[i - 1].second);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  std::map<std::uint32_t, std::vector<std::uint32_t>> groups;  // root -> pairs
  for (std::uint32_t i = 0; i < subset.size(); ++i)
    groups[find_root(parent, i)].push_back(subset[i]);
  std::vector<std::vector<std::uint32_t>> result;
  result.reserve(groups.size());
  for (auto& [root, members] : groups) result.push_back(std::move(members));
  return result;
}

// How far `vertices` reach from the plane of the loop made of `loop`'s pair boundaries, in
// units of the loop's mean radius; 0 for a loop of no extent.
double protrusion(const Mesh& mesh, const std::vector<ClusterPairBoundary>& pairs,
                  const std::vector<std::uint32_t>& loop,
                  const std::vector<std::uint32_t>& vertices) {
  std::vector<std::uint32_t> loop_vertices;
  for (const std::uint32_t p : loop)
    loop_vertices.insert(loop_vertices.end(), pairs[p].vertices.begin(), pairs[p].vertices.end());
  std::sort(loop_vertices.begin(), loop_vertices.end());
  loop_vertices.erase(std::unique(loop_vertices.begin(), loop_vertices.end()), loop_vertices.end());
  Vec3 centre{0, 0, 0};
  for (const std::uint32_t v : loop_vertices) centre = centre + mesh.positions[v];
  centre = (1.0 / static_cast<double>(loop_vertices.size())) * centre;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  double radius = 0;
  for (const std::uint32_t v : loop_vertices) {
    const Vec3 d = mesh.positions[v] - centre;
    const Eigen::Vector3d e(d[0], d[1], d[2]);
    scatter += e * e.transpose();
    radius += norm(d);
  }
  radius /= static_cast<double>(loop_vertices.size());
  if (!(radius > 0)) return 0;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  const Eigen::Vector3d smallest = solver.eigenvectors().col(0);
  const Vec3 normal{smallest[0], smallest[1], smallest[2]};
  double reach = 0;
  for (const std::uint32_t v : vertices)
    reach = std::max(reach, std::abs(dot(mesh.positions[v] - centre, normal)));
  return reach / radius;
}

// The limbs of JointRule::Limbs, by decreasing protrusion; a limb whose loop shares a pair with
// one before it is left out.
std::vector<Limb> find_limbs(const Mesh& mesh, const std::vector<ClusterPairBoundary>& pairs,
                             const std::vector<std::vector<std::uint32_t>>& cluster_vertices,
                             double min_protrusion) {
  const std::size_t k = cluster_vertices.size();
  std::vector<std::vector<std::uint32_t>> own(k);  // pairs of each cluster
  for (std::uint32_t p = 0; p < pairs.size(); ++p) {
    own[pairs[p].first].push_back(p);
    own[pairs[p].second].push_back(p);
  }
  const auto other = [&](std::uint32_t p, std::uint32_t c) { return across(pairs[p], c); };
  // Depth-first search from the lowest cluster of each part of the adjacency graph (where the
  // skinning's tree starts it), for what that part falls into without one cluster c (Hopcroft
  // and Tarjan's articulation points): each child subtree of c that no edge leads out of above
  // c, and the rest, which holds the start.
  std::vector<std::uint32_t> found(k, kNone), subtree_end(k), low(k), parent(k, kNone);
  std::vector<std::vector<std::uint32_t>> children(k);
  std::vector<std::pair<std::uint32_t, std::size_t>> stack;  // cluster, next of its pairs
  std::uint32_t time = 0;
  for (std::uint32_t start = 0; start < k; ++start) {
    if (found[start] != kNone) continue;
    found[start] = low[start] = time++;
    stack.assign(1, {start, 0});
    while (!stack.empty()) {
      const std::uint32_t c = stack.back().first;
      if (stack.back().second < own[c].size()) {
        const std::uint32_t next = other(own[c][stack.back().second++], c);
        if (found[next] == kNone) {
          parent[next] = c;
          children[c].push_back(next);
          found[next] = low[next] = time++;
          stack.emplace_back(next, 0);
        } else if (next != parent[c]) {
          low[c] = std::min(low[c], found[next]);
        }
        continue;
      }
      subtree_end[c] = time;
      stack.pop_back();
      if (parent[c] != kNone) low[parent[c]] = std::min(low[parent[c]], low[c]);
    }
  }
  // The part of the graph without c that holds its neighbour x: a child of c that roots it, or
  // c itself for the part with the start.
  const auto part_of = [&](std::uint32_t c, std::uint32_t x) {
    if (found[x] <= found[c] || found[x] >= subtree_end[c]) return c;  // not below c
    const std::vector<std::uint32_t>& below = children[c];
    const std::uint32_t child = *(std::upper_bound(below.begin(), below.end(), found[x],
                                                   [&](std::uint32_t time_of_x, std::uint32_t b) {
                                                     return time_of_x < found[b];
                                                   }) -
                                  1);
    return low[child] >= found[c] ? child : c;
  };
  std::vector<Limb> limbs;
  for (std::uint32_t c = 0; c < k; ++c) {
    if (parent[c] == kNone) continue;  // the start of its part
    const std::vector<std::vector<std::uint32_t>> loops = touching_groups(pairs, own[c]);
    // Each loop must lead to one part, and no other loop to that part.
    std::vector<std::uint32_t> loop_part;
    bool separating = true;
    for (const std::vector<std::uint32_t>& loop : loops) {
      const std::uint32_t part = part_of(c, other(loop.front(), c));
      for (const std::uint32_t p : loop) separating = separating && part_of(c, other(p, c)) == part;
      separating =
          separating && std::find(loop_part.begin(), loop_part.end(), part) == loop_part.end();
      loop_part.push_back(part);
    }
    if (!separating) continue;
    const auto attachment = static_cast<std::size_t>(
        std::find(loop_part.begin(), loop_part.end(), c) - loop_part.begin());
    if (attachment == loops.size()) continue;  // (c's parent is in some loop's part: not reached)
    const double reach = protrusion(mesh, pairs, loops[attachment], cluster_vertices[c]);
    if (reach >= min_protrusion) limbs.push_back({c, loops[attachment], reach});
  }
  std::stable_sort(limbs.begin(), limbs.end(),
                   [](const Limb& a, const Limb& b) { return a.protrusion > b.protrusion; });
  std::vector<bool> taken(pairs.size(), false);
  std::vector<Limb> kept;
  for (Limb& limb : limbs) {
    if (std::any_of(limb.loop.begin(), limb.loop.end(), [&](std::uint32_t p) { return taken[p]; }))
      continue;
    for (const std::uint32_t p : limb.loop) taken[p] = true;
    kept.push_back(std::move(limb));
  }
  return kept;
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
  // Up to two distinct neighbours: more change nothing, and a hub's bones can be many.
  std::vector<std::uint32_t> neighbours;
  for (const std::uint32_t j : bone.joints) {
    for (const std::uint32_t b : skeleton.joints[j].bones) {
      if (b == c || std::find(neighbours.begin(), neighbours.end(), b) != neighbours.end())
        continue;
      neighbours.push_back(b);
      if (neighbours.size() == 2) break;
    }
    if (neighbours.size() == 2) break;
  }
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
                          std::span<const Primitive> primitives, const SkeletonOptions& options) {
  check_input(mesh, face_labels, primitives);
  if (!(std::isfinite(options.limb_protrusion) && options.limb_protrusion >= 0))
    throw InvalidInputError("extract_skeleton: limb_protrusion must be a finite number >= 0");
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
  const std::vector<Limb> limbs =
      options.joints == JointRule::Limbs
          ? find_limbs(mesh, pairs, cluster_vertices, options.limb_protrusion)
          : std::vector<Limb>{};
  std::vector<bool> taken(pairs.size(), false), at_limb(mesh.vertex_count(), false);
  for (const Limb& limb : limbs)
    for (const std::uint32_t p : limb.loop) {
      taken[p] = true;
      for (const std::uint32_t v : pairs[p].vertices) at_limb[v] = true;
    }
  // Every joint's pairs, limbs' loops (the limb's index) and merged touching boundaries (kNone),
  // numbered by their lowest boundary vertex.
  std::vector<std::tuple<std::uint32_t, std::uint32_t, std::vector<std::uint32_t>>> groups;
  const auto lowest_vertex = [&](const std::vector<std::uint32_t>& members) {
    std::uint32_t lowest = kNone;
    for (const std::uint32_t p : members) lowest = std::min(lowest, pairs[p].vertices.front());
    return lowest;
  };
  for (std::uint32_t i = 0; i < limbs.size(); ++i)
    groups.emplace_back(lowest_vertex(limbs[i].loop), i, limbs[i].loop);
  std::vector<std::uint32_t> free_pairs;  // the paper's joints: the other pairs, by touch
  for (std::uint32_t p = 0; p < pairs.size(); ++p)
    if (!taken[p]) free_pairs.push_back(p);
  for (std::vector<std::uint32_t>& members : touching_groups(pairs, free_pairs))
    groups.emplace_back(lowest_vertex(members), kNone, std::move(members));
  std::sort(groups.begin(), groups.end());
  const auto touches_limb = [&](std::uint32_t p) {
    return std::any_of(pairs[p].vertices.begin(), pairs[p].vertices.end(),
                       [&](std::uint32_t v) { return at_limb[v]; });
  };
  for (const auto& [lowest, limb, members] : groups) {
    Joint joint =
        boundary_joint(mesh, pairs, members, static_cast<std::uint32_t>(skeleton.joints.size()));
    if (limb != kNone) {  // between the limb and the neighbour it shares the most boundary with
      const std::uint32_t c = limbs[limb].cluster;
      std::uint32_t longest = members.front();
      for (const std::uint32_t p : members)
        if (pairs[p].length > pairs[longest].length) longest = p;
      const std::uint32_t parent = across(pairs[longest], c);
      joint.bones = {std::min(c, parent), std::max(c, parent)};
      joint.kind = JointKind::Sensitive;
    } else if (!limbs.empty() && std::any_of(members.begin(), members.end(), touches_limb)) {
      joint.kind = JointKind::Locked;  // what a limb hangs from stays rigid
    }
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

Skeleton extract_skeleton(const Hierarchy& hierarchy, const Segmentation& segmentation,
                          const SkeletonOptions& options) {
  return extract_skeleton(hierarchy.mesh(), segmentation.labels,
                          cluster_primitives(describe_clusters(hierarchy, segmentation)), options);
}

}  // namespace primseg
