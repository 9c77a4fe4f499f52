#include "primseg/refine.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "face_adjacency.hpp"
#include "no_index.hpp"
#include "primseg/error.hpp"
#include "working_primitive.hpp"

namespace primseg {
namespace {

using detail::kNone;
using Adjacency = detail::FaceAdjacency;
// How far above the cut's total error (over the corners) refinement may take it: passes trade a
// little of it for borders the corners cannot see (measured on the generated CAD-tessellated
// shapes: a chamfered cylinder's borders move right while its corner error rises by 0.1%).
constexpr double kAllowedErrorRise = 0.05;

// Connected components (edge-connected through the dual graph) of the clusters of a labelling.
struct Components {
  std::vector<std::uint32_t> of_face;  // component of each face
  std::vector<std::uint32_t> size;     // faces of each component, in order of lowest face
  std::vector<std::uint32_t> count;    // components of each cluster

  Components(const Adjacency& adjacency, const std::vector<std::uint32_t>& labels,
             std::uint32_t clusters)
      : of_face(labels.size(), kNone), count(clusters, 0) {
    std::vector<std::uint32_t> stack;
    for (std::uint32_t start = 0; start < labels.size(); ++start) {
      if (of_face[start] != kNone) continue;
      const auto id = static_cast<std::uint32_t>(size.size());
      size.push_back(0);
      ++count[labels[start]];
      of_face[start] = id;
      stack.push_back(start);
      while (!stack.empty()) {
        const std::uint32_t f = stack.back();
        stack.pop_back();
        ++size[id];
        for (std::uint32_t i = adjacency.offset[f]; i < adjacency.offset[f + 1]; ++i) {
          const std::uint32_t g = adjacency.neighbour[i];
          if (of_face[g] == kNone && labels[g] == labels[f]) {
            of_face[g] = id;
            stack.push_back(g);
          }
        }
      }
    }
  }
};

// Undoes the moves of a pass that split a cluster, until no cluster has more components than at
// the start (`initial`). A cluster that was connected keeps its largest piece (ties: the one
// with the lowest face); the moves next to its other pieces are undone, layer by layer, which
// reconnects them through the faces that had left, and leaves the moves elsewhere on its border.
// After kLayers layers, or for a cluster that was not connected to begin with, every move into
// or out of a split cluster is undone, which at worst restores the connected start of the pass.
void undo_splitting_moves(const Adjacency& adjacency, const std::vector<std::uint32_t>& initial,
                          std::vector<std::uint32_t>& moves,
                          const std::vector<std::uint32_t>& origin,
                          std::vector<std::uint32_t>& labels) {
  constexpr int kLayers = 16;
  const auto k = static_cast<std::uint32_t>(initial.size());
  for (int layer = 0;; ++layer) {
    const Components components(adjacency, labels, k);
    std::vector<char> split(k, 0);
    bool any = false;
    for (std::uint32_t c = 0; c < k; ++c)
      if (components.count[c] > initial[c]) split[c] = 1, any = true;
    if (!any) return;
    // The piece each split cluster keeps, if it keeps one.
    std::vector<std::uint32_t> kept_piece(k, kNone);
    if (layer < kLayers)
      for (std::uint32_t f = 0; f < labels.size(); ++f) {
        const std::uint32_t c = labels[f], piece = components.of_face[f];
        if (split[c] && initial[c] == 1 &&
            (kept_piece[c] == kNone || components.size[piece] > components.size[kept_piece[c]]))
          kept_piece[c] = piece;
      }
    auto cut_off_next_to = [&](std::uint32_t f, std::uint32_t c) {
      for (std::uint32_t i = adjacency.offset[f]; i < adjacency.offset[f + 1]; ++i) {
        const std::uint32_t g = adjacency.neighbour[i];
        if (labels[g] == c && components.of_face[g] != kept_piece[c]) return true;
      }
      return false;
    };
    std::vector<std::uint32_t> kept;
    for (std::uint32_t f : moves) {
      const std::uint32_t from = origin[f], to = labels[f];
      const bool undo = (split[from] && (kept_piece[from] == kNone || cut_off_next_to(f, from))) ||
                        (split[to] && kept_piece[to] == kNone);
      if (undo)
        labels[f] = from;
      else
        kept.push_back(f);
    }
    moves = std::move(kept);
  }
}

// ∫ d² over face f's triangles (working frame), by the edge-midpoint rule.
double face_error(const Hierarchy& hierarchy, std::uint32_t f, const Primitive& working,
                  const std::vector<std::uint32_t>& first_triangle) {
  const DualGraph& graph = hierarchy.graph();
  double sum = 0;
  for (std::uint32_t t = first_triangle[f]; t < first_triangle[f + 1]; ++t) {
    const Triangle tri = graph.corners(t);
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

// Σ w d² of every cluster to its reported primitive, over the triangle corners weighted as in
// the hierarchy: the error the reports' RMS values measure.
double total_squared_error(const Hierarchy& hierarchy, const std::vector<std::uint32_t>& labels,
                           const std::vector<ClusterReport>& reports) {
  const Mesh& mesh = hierarchy.mesh();
  std::vector<double> weight(reports.size(), 0);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::array<double, 3> w = hierarchy.graph().corner_weights(t);
    weight[labels[mesh.face_of_triangle[t]]] += w[0] + w[1] + w[2];
  }
  double sum = 0;
  for (std::size_t c = 0; c < reports.size(); ++c)
    sum += reports[c].rms * reports[c].rms * weight[c];
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
  const std::vector<std::uint32_t> initial_components = Components(adjacency, labels, k).count;
  std::vector<std::uint32_t> sizes(k, 0);
  for (std::uint32_t label : labels) ++sizes[label];
  const double cut_error = total_squared_error(hierarchy, labels, result.reports);

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
    undo_splitting_moves(adjacency, initial_components, moves, origin, labels);
    if (moves.empty()) break;
    std::vector<Primitive> start(k);
    for (std::uint32_t c = 0; c < k; ++c) start[c] = result.reports[c].primitive;
    std::vector<ClusterReport> refitted =
        describe_clusters(hierarchy, result.segmentation, start, options.describe);
    // A face is judged over its flat triangles, which see what its corners cannot (the faces of
    // a CAD fan have all their corners on feature curves, on both surfaces), but which a curved
    // primitive misses by the tessellation's sagitta: the faces of an exact cylinder can look
    // closer to the plane it turns into. So a pass stops the refinement if it leaves the clusters'
    // total error over the corners (what the tree and the reports measure) more than
    // kAllowedErrorRise above the cut's.
    if (total_squared_error(hierarchy, labels, refitted) > (1 + kAllowedErrorRise) * cut_error) {
      for (std::uint32_t f : moves) labels[f] = origin[f];  // the labels at the start of the pass
      break;
    }
    result.reports = std::move(refitted);
    for (std::uint32_t f : moves) --sizes[origin[f]], ++sizes[labels[f]];
    result.moved_faces += static_cast<std::uint32_t>(moves.size());
    ++result.passes;
  }
  // Reported as the tree's fit of the node each cluster grew from, not the previous pass's.
  for (ClusterReport& r : result.reports) r.algebraic = hierarchy.primitive(r.node);
  return result;
}

}  // namespace primseg
