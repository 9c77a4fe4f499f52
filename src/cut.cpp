#include "primseg/cut.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "primseg/error.hpp"

namespace primseg {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

// Numbers the clusters given by `cluster_of_face` (arbitrary ids < nodes.size()) by decreasing
// area, ties by lowest face.
Segmentation number_clusters(const Hierarchy& hierarchy, std::vector<std::uint32_t> cluster_of_face,
                             std::vector<std::uint32_t> nodes) {
  const Mesh& mesh = hierarchy.mesh();
  const DualGraph& graph = hierarchy.graph();
  const std::size_t k = nodes.size();
  std::vector<double> area(k, 0.0);
  std::vector<std::uint32_t> lowest(k, kNone);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t)
    area[cluster_of_face[mesh.face_of_triangle[t]]] += graph.triangle_area(t);
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f)
    lowest[cluster_of_face[f]] = std::min(lowest[cluster_of_face[f]], f);
  std::vector<std::uint32_t> order(k);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    if (area[a] != area[b]) return area[a] > area[b];
    return lowest[a] < lowest[b];
  });
  std::vector<std::uint32_t> rank(k);
  Segmentation result;
  result.nodes.resize(k);
  for (std::uint32_t r = 0; r < k; ++r) {
    rank[order[r]] = r;
    result.nodes[r] = nodes[order[r]];
  }
  for (std::uint32_t& c : cluster_of_face) c = rank[c];
  result.labels = std::move(cluster_of_face);
  return result;
}

// Labels faces from a set of kept nodes, where `kept[node]` holds the cluster id of a kept
// node and kNone otherwise; every leaf must have exactly one kept ancestor-or-self.
std::vector<std::uint32_t> label_faces(const Hierarchy& hierarchy,
                                       std::vector<std::uint32_t>& kept) {
  const std::uint32_t f = hierarchy.face_count();
  const auto merges = hierarchy.merges();
  // Parents come after children: walk down from the top so every node inherits its label.
  for (std::uint32_t i = static_cast<std::uint32_t>(merges.size()); i-- > 0;) {
    const std::uint32_t label = kept[f + i];
    if (label == kNone) continue;
    for (std::uint32_t child : {merges[i].first, merges[i].second})
      if (kept[child] == kNone) kept[child] = label;
  }
  return {kept.begin(), kept.begin() + f};
}

}  // namespace

Segmentation cut_by_count(const Hierarchy& hierarchy, std::uint32_t clusters) {
  const std::uint32_t f = hierarchy.face_count();
  if (clusters < 1 || clusters > f)
    throw InvalidInputError("the number of clusters must be between 1 and " + std::to_string(f) +
                            ", not " + std::to_string(clusters));
  const std::uint32_t real = f - hierarchy.component_count();
  const std::uint32_t applied = std::min(real, f - clusters);
  // The kept nodes: applied merges' nodes whose parent is not applied, and leaves whose parent
  // is not applied.
  std::vector<std::uint32_t> kept(hierarchy.node_count(), kNone);
  std::vector<std::uint32_t> nodes;
  const auto& parents = hierarchy.parents();
  auto is_applied = [&](std::uint32_t node) { return node >= f && node - f < applied; };
  for (std::uint32_t node = 0; node < f + applied; ++node) {
    const std::uint32_t parent = parents[node];
    if (parent == kNone || !is_applied(parent)) {
      kept[node] = static_cast<std::uint32_t>(nodes.size());
      nodes.push_back(node);
    }
  }
  auto labels = label_faces(hierarchy, kept);
  return number_clusters(hierarchy, std::move(labels), std::move(nodes));
}

Segmentation cut_by_tolerance(const Hierarchy& hierarchy, double tolerance) {
  if (!(tolerance >= 0) || !std::isfinite(tolerance))
    throw InvalidInputError("the tolerance must be a non-negative number");
  const std::uint32_t f = hierarchy.face_count();
  const auto merges = hierarchy.merges();
  std::vector<std::uint32_t> kept(hierarchy.node_count(), kNone);
  std::vector<std::uint32_t> nodes;
  std::vector<std::uint32_t> stack;
  // Component roots: the children of trailing merges that are not trailing merges themselves,
  // or the single root.
  for (std::uint32_t node = 0; node < hierarchy.node_count(); ++node) {
    const std::uint32_t parent = hierarchy.parents()[node];
    const bool is_trailing = node >= f && merges[node - f].trailing;
    if (!is_trailing && (parent == kNone || merges[parent - f].trailing)) stack.push_back(node);
  }
  std::reverse(stack.begin(), stack.end());
  while (!stack.empty()) {
    const std::uint32_t node = stack.back();
    stack.pop_back();
    if (hierarchy.is_leaf(node) || hierarchy.rms_estimate(node) <= tolerance) {
      kept[node] = static_cast<std::uint32_t>(nodes.size());
      nodes.push_back(node);
    } else {
      stack.push_back(merges[node - f].second);
      stack.push_back(merges[node - f].first);
    }
  }
  auto labels = label_faces(hierarchy, kept);
  return number_clusters(hierarchy, std::move(labels), std::move(nodes));
}

std::vector<ClusterReport> describe_clusters(const Hierarchy& hierarchy,
                                             const Segmentation& segmentation) {
  const Mesh& mesh = hierarchy.mesh();
  const DualGraph& graph = hierarchy.graph();
  const WorkingFrame& frame = graph.frame();
  const std::uint32_t k = segmentation.cluster_count();
  std::vector<ClusterReport> reports(k);
  std::vector<Primitive> working(k);
  for (std::uint32_t c = 0; c < k; ++c) {
    ClusterReport& r = reports[c];
    r.id = c;
    r.node = segmentation.nodes[c];
    r.primitive = hierarchy.primitive(r.node);
    r.face_count = hierarchy.face_count(r.node);
    // Distances are measured in the working frame (no overflow for huge inputs) and scaled back.
    Primitive w = r.primitive;
    const Eigen::Vector3d p = frame.to_working(r.primitive.point);
    w.point = {p.x(), p.y(), p.z()};
    w.radius = std::ldexp(r.primitive.radius, -frame.exponent);
    w.minor_radius = std::ldexp(r.primitive.minor_radius, -frame.exponent);
    working[c] = w;
  }
  std::vector<double> sum_wd2(k, 0.0), sum_w(k, 0.0), max_d(k, 0.0);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::uint32_t c = segmentation.labels[mesh.face_of_triangle[t]];
    const std::array<double, 3> w = graph.corner_weights(t);
    for (int corner = 0; corner < 3; ++corner) {
      const Eigen::Vector3d& x = graph.position(mesh.triangles[t][corner]);
      const double d = working[c].distance({x.x(), x.y(), x.z()});
      sum_wd2[c] += w[corner] * d * d;
      sum_w[c] += w[corner];
      max_d[c] = std::max(max_d[c], d);
    }
    reports[c].area += graph.triangle_area(t);
  }
  for (std::uint32_t c = 0; c < k; ++c) {
    reports[c].rms =
        sum_w[c] > 0 ? std::ldexp(std::sqrt(sum_wd2[c] / sum_w[c]), frame.exponent) : 0.0;
    reports[c].max = std::ldexp(max_d[c], frame.exponent);
    reports[c].area = std::ldexp(reports[c].area, 2 * frame.exponent);
  }
  return reports;
}

std::vector<std::array<double, 4>> scipy_linkage(const Hierarchy& hierarchy) {
  const std::span<const Merge> merges = hierarchy.merges();
  std::vector<std::array<double, 4>> rows(merges.size());
  double height = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < merges.size(); ++i) {
    const Merge& merge = merges[i];
    height = i == 0 ? merge.cost
                    : std::max(merge.cost,
                               std::nextafter(height, std::numeric_limits<double>::infinity()));
    rows[i] = {double(merge.first), double(merge.second), height, double(merge.face_count)};
  }
  return rows;
}

}  // namespace primseg
