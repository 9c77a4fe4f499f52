#include "primseg/refine.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "primseg/error.hpp"
#include "working_primitive.hpp"

namespace primseg {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

// Dual-graph neighbours of every face, as offsets into one array.
struct Adjacency {
  std::vector<std::uint32_t> offset, neighbour;

  explicit Adjacency(const DualGraph& graph) : offset(graph.face_count() + 1, 0) {
    for (const DualEdge& e : graph.edges()) ++offset[e.first + 1], ++offset[e.second + 1];
    std::partial_sum(offset.begin(), offset.end(), offset.begin());
    neighbour.resize(offset.back());
    std::vector<std::uint32_t> next(offset.begin(), offset.end() - 1);
    for (const DualEdge& e : graph.edges()) {
      neighbour[next[e.first]++] = e.second;
      neighbour[next[e.second]++] = e.first;
    }
  }
};

// Connected components of each cluster (edge-connected through the dual graph).
std::vector<std::uint32_t> component_counts(const Adjacency& adjacency,
                                            const std::vector<std::uint32_t>& labels,
                                            std::uint32_t clusters) {
  std::vector<std::uint32_t> count(clusters, 0);
  std::vector<char> seen(labels.size(), 0);
  std::vector<std::uint32_t> stack;
  for (std::uint32_t start = 0; start < labels.size(); ++start) {
    if (seen[start]) continue;
    ++count[labels[start]];
    seen[start] = 1;
    stack.push_back(start);
    while (!stack.empty()) {
      const std::uint32_t f = stack.back();
      stack.pop_back();
      for (std::uint32_t i = adjacency.offset[f]; i < adjacency.offset[f + 1]; ++i) {
        const std::uint32_t g = adjacency.neighbour[i];
        if (!seen[g] && labels[g] == labels[f]) {
          seen[g] = 1;
          stack.push_back(g);
        }
      }
    }
  }
  return count;
}

// ∫ d² over face f's triangles (working frame), by the edge-midpoint rule.
double face_error(const Hierarchy& hierarchy, std::uint32_t f, const Primitive& working,
                  const std::vector<std::uint32_t>& first_triangle) {
  const Mesh& mesh = hierarchy.mesh();
  const DualGraph& graph = hierarchy.graph();
  double sum = 0;
  for (std::uint32_t t = first_triangle[f]; t < first_triangle[f + 1]; ++t) {
    const Triangle& tri = mesh.triangles[t];
    double squares = 0;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d m = 0.5 * (graph.position(tri[k]) + graph.position(tri[(k + 1) % 3]));
      const double d = working.distance({m.x(), m.y(), m.z()});
      squares += d * d;
    }
    sum += graph.triangle_area(t) * squares / 3;
  }
  return sum;
}

}  // namespace

RefinedLevel refine_boundaries(const Hierarchy& hierarchy, const Segmentation& segmentation,
                               const BoundaryRefinementOptions& options) {
  const Mesh& mesh = hierarchy.mesh();
  const std::uint32_t f_count = mesh.face_count(), k = segmentation.cluster_count();
  if (segmentation.labels.size() != f_count)
    throw InvalidInputError("refine_boundaries: the segmentation has " +
                            std::to_string(segmentation.labels.size()) + " labels for " +
                            std::to_string(f_count) + " faces");
  if (!(options.improvement > 0) || !std::isfinite(options.improvement))
    throw InvalidInputError("refine_boundaries: the improvement factor must be positive");
  const Adjacency adjacency(hierarchy.graph());
  std::vector<std::uint32_t> first_triangle(f_count + 1, 0);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t)
    ++first_triangle[mesh.face_of_triangle[t] + 1];
  std::partial_sum(first_triangle.begin(), first_triangle.end(), first_triangle.begin());

  RefinedLevel result;
  result.segmentation = segmentation;
  std::vector<std::uint32_t>& labels = result.segmentation.labels;
  result.reports = describe_clusters(hierarchy, result.segmentation, options.describe);
  const std::vector<std::uint32_t> initial_components = component_counts(adjacency, labels, k);
  std::vector<std::uint32_t> sizes(k, 0);
  for (std::uint32_t label : labels) ++sizes[label];

  for (std::uint32_t pass = 0; pass < options.max_passes; ++pass) {
    std::vector<Primitive> working(k);
    for (std::uint32_t c = 0; c < k; ++c)
      working[c] = detail::to_working(hierarchy.graph().frame(), result.reports[c].primitive);
    // Decide every move against the labels at the start of the pass.
    std::vector<std::uint32_t> target(f_count, kNone);
    std::vector<std::uint32_t> leaving(k, 0);
    for (std::uint32_t f = 0; f < f_count; ++f) {
      const std::uint32_t own = labels[f];
      double own_error = -1, best_error = std::numeric_limits<double>::infinity();
      std::uint32_t best = kNone;
      for (std::uint32_t i = adjacency.offset[f]; i < adjacency.offset[f + 1]; ++i) {
        const std::uint32_t other = labels[adjacency.neighbour[i]];
        if (other == own || other == best) continue;
        if (own_error < 0) own_error = face_error(hierarchy, f, working[own], first_triangle);
        const double error = face_error(hierarchy, f, working[other], first_triangle);
        if (error < best_error || (error == best_error && other < best))
          best_error = error, best = other;
      }
      if (best != kNone && best_error < options.improvement * own_error) target[f] = best;
    }
    // No cluster may lose all its faces: the last faces of a cluster stay.
    std::vector<std::uint32_t> moves;
    for (std::uint32_t f = 0; f < f_count; ++f)
      if (target[f] != kNone && leaving[labels[f]] + 1 < sizes[labels[f]]) {
        ++leaving[labels[f]];
        moves.push_back(f);
      }
    std::vector<std::uint32_t> origin(f_count);
    for (std::uint32_t f : moves) origin[f] = labels[f], labels[f] = target[f];
    // Undo every move touching a cluster that split, until none does (at worst all moves are
    // undone, which restores the connected start of the pass).
    for (;;) {
      const std::vector<std::uint32_t> components = component_counts(adjacency, labels, k);
      std::vector<char> split(k, 0);
      bool any = false;
      for (std::uint32_t c = 0; c < k; ++c)
        if (components[c] > initial_components[c]) split[c] = 1, any = true;
      if (!any) break;
      std::vector<std::uint32_t> kept;
      for (std::uint32_t f : moves) {
        if (split[origin[f]] || split[labels[f]])
          labels[f] = origin[f];
        else
          kept.push_back(f);
      }
      moves = std::move(kept);
    }
    if (moves.empty()) break;
    for (std::uint32_t f : moves) --sizes[origin[f]], ++sizes[labels[f]];
    result.moved_faces += static_cast<std::uint32_t>(moves.size());
    ++result.passes;
    std::vector<Primitive> start(k);
    for (std::uint32_t c = 0; c < k; ++c) start[c] = result.reports[c].primitive;
    result.reports = describe_clusters(hierarchy, result.segmentation, start, options.describe);
  }
  // Reported as the tree's fit of the node each cluster grew from, not the previous pass's.
  for (ClusterReport& r : result.reports) r.algebraic = hierarchy.primitive(r.node);
  return result;
}

}  // namespace primseg
