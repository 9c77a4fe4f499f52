#include "primseg/cut.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "cluster_numbering.hpp"
#include "cluster_triangles.hpp"
#include "no_index.hpp"
#include "parallel.hpp"
#include "primseg/error.hpp"
#include "tree_nodes.hpp"
#include "triangle_corners.hpp"
#include "working_primitive.hpp"

namespace primseg {
namespace {

using detail::kNone;

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
  detail::sort_into_label_order(
      order, [&](std::uint32_t c) { return area[c]; }, [&](std::uint32_t c) { return lowest[c]; });
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
  std::vector<std::uint32_t> nodes = detail::level_nodes(hierarchy, clusters);
  std::vector<std::uint32_t> kept(hierarchy.node_count(), kNone);
  for (std::uint32_t c = 0; c < nodes.size(); ++c) kept[nodes[c]] = c;
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
                                             const Segmentation& segmentation,
                                             const DescribeOptions& options) {
  std::vector<Primitive> start(segmentation.cluster_count());
  for (std::uint32_t c = 0; c < start.size(); ++c)
    start[c] = hierarchy.primitive(segmentation.nodes[c]);
  return describe_clusters(hierarchy, segmentation, start, options);
}

namespace {

// Fills the primitive, rms and max of a report from the cluster's corners (working frame, in
// ascending triangle order: describe_clusters and describe_nodes give the same bits) and its
// area from the working-frame sum.
void fit_report(const WorkingFrame& frame, const Primitive& start, std::span<const Vec3> points,
                std::span<const double> weights, const DescribeOptions& options, ClusterReport& r) {
  GeometricFitOptions fit_options = options.fit;
  if (!options.geometric_fit) fit_options.max_iterations = 0;
  r.algebraic = start;
  // Fitted and measured in the working frame (no overflow for huge inputs), scaled back.
  const GeometricFit fit =
      fit_geometric_or_sphere(detail::to_working(frame, start), points, weights, fit_options);
  r.primitive = fit.iterations > 0 ? frame.to_input(fit.primitive) : start;
  r.rms = std::ldexp(fit.rms, frame.exponent);
  r.max = std::ldexp(fit.max, frame.exponent);
  r.area = std::ldexp(r.area, 2 * frame.exponent);
}

}  // namespace

std::vector<ClusterReport> describe_clusters(const Hierarchy& hierarchy,
                                             const Segmentation& segmentation,
                                             const std::vector<Primitive>& start,
                                             const DescribeOptions& options) {
  const Mesh& mesh = hierarchy.mesh();
  const DualGraph& graph = hierarchy.graph();
  const std::uint32_t k = segmentation.cluster_count();
  if (start.size() != k || segmentation.labels.size() != mesh.face_count())
    throw InvalidInputError("describe_clusters: the segmentation does not match the mesh");
  for (std::uint32_t label : segmentation.labels)
    if (label >= k)
      throw InvalidInputError("describe_clusters: a label is not below the cluster count");
  const detail::ClusterTriangles clusters(mesh, segmentation.labels, k);
  std::vector<ClusterReport> reports(k);
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f)
    ++reports[segmentation.labels[f]].face_count;
  // Each cluster on its own: the same result for any thread count.
  const unsigned threads = detail::thread_count(options.threads);
  std::vector<std::vector<Vec3>> points(threads);
  std::vector<std::vector<double>> weights(threads);
  detail::parallel_for_threads(k, threads, [&](std::size_t c, unsigned thread) {
    ClusterReport& r = reports[c];
    r.id = static_cast<std::uint32_t>(c);
    r.node = segmentation.nodes[c];
    points[thread].clear();
    weights[thread].clear();
    for (const std::uint32_t t : clusters.of(c)) {
      detail::append_corners(graph, t, points[thread], weights[thread]);
      r.area += graph.triangle_area(t);
    }
    fit_report(graph.frame(), start[c], points[thread], weights[thread], options, r);
  });
  return reports;
}

std::vector<Primitive> cluster_primitives(std::span<const ClusterReport> reports) {
  std::vector<Primitive> primitives;
  primitives.reserve(reports.size());
  for (const ClusterReport& report : reports) primitives.push_back(report.primitive);
  return primitives;
}

std::vector<ClusterReport> describe_nodes(const Hierarchy& hierarchy,
                                          std::span<const std::uint32_t> nodes,
                                          const DescribeOptions& options) {
  const DualGraph& graph = hierarchy.graph();
  for (const std::uint32_t node : nodes)
    detail::check_cluster_node(hierarchy, node, "describe_nodes");
  const detail::LeafOrder leaves(hierarchy);

  std::vector<ClusterReport> reports(nodes.size());
  const unsigned threads = detail::thread_count(options.threads);
  std::vector<std::vector<std::uint32_t>> faces(threads);
  std::vector<std::vector<Vec3>> points(threads);
  std::vector<std::vector<double>> weights(threads);
  detail::parallel_for_threads(nodes.size(), threads, [&](std::size_t i, unsigned thread) {
    ClusterReport& r = reports[i];
    r.id = static_cast<std::uint32_t>(i);
    r.node = nodes[i];
    r.face_count = hierarchy.face_count(r.node);
    std::vector<std::uint32_t>& node_faces = faces[thread];
    leaves.ascending_faces(hierarchy, r.node, node_faces);
    points[thread].clear();
    weights[thread].clear();
    for (std::uint32_t face : node_faces)
      for (std::uint32_t t = graph.first_triangle(face); t < graph.first_triangle(face + 1); ++t) {
        detail::append_corners(graph, t, points[thread], weights[thread]);
        r.area += graph.triangle_area(t);
      }
    fit_report(graph.frame(), hierarchy.primitive(r.node), points[thread], weights[thread], options,
               r);
  });
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
