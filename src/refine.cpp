#include "primseg/refine.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <string>

#include "cluster_triangles.hpp"
#include "face_adjacency.hpp"
#include "face_triangles.hpp"
#include "geometric_models.hpp"
#include "model_selection.hpp"
#include "no_index.hpp"
#include "parallel.hpp"
#include "primseg/cluster_view.hpp"
#include "primseg/error.hpp"
#include "primseg/primitives/primitive_fitter.hpp"
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

// The reports' primitives in the working frame, where faces are measured.
std::vector<Primitive> working_primitives(const Hierarchy& hierarchy,
                                          const std::vector<ClusterReport>& reports) {
  std::vector<Primitive> working;
  working.reserve(reports.size());
  for (const ClusterReport& r : reports)
    working.push_back(detail::to_working(hierarchy.graph().frame(), r.primitive));
  return working;
}

// Area of face f's triangles (working frame).
double face_area(const Hierarchy& hierarchy, std::uint32_t f,
                 const std::vector<std::uint32_t>& first_triangle) {
  double area = 0;
  for (std::uint32_t t = first_triangle[f]; t < first_triangle[f + 1]; ++t)
    area += hierarchy.graph().triangle_area(t);
  return area;
}

// Each cluster's noise (working frame): the standard deviation of its vertices' signed
// distances s to its primitive that varies from vertex to vertex. For two triangles of the
// cluster sharing an edge ab, with c and d their other corners, s_c + s_d - s_a - s_b cancels any
// misfit linear across them (exactly on a parallelogram), so a misfit shows only by its
// curvature over one edge, while independent noise gives it a standard deviation of 2σ; the
// median over the cluster's edges (/ 0.6745) ignores the few edges along a crease the cluster
// straddles. 0 for a cluster without such a pair (polygon faces are left out).
std::vector<double> cluster_noise(const Hierarchy& hierarchy,
                                  const std::vector<std::uint32_t>& labels,
                                  const std::vector<Primitive>& working,
                                  const std::vector<std::uint32_t>& first_triangle) {
  const DualGraph& graph = hierarchy.graph();
  const auto single_triangle = [&](std::uint32_t f) {
    return first_triangle[f + 1] == first_triangle[f] + 1;
  };
  // The signed distance of every corner of a single-triangle face to its cluster's primitive.
  std::vector<std::unique_ptr<detail::GeometricModel>> models(working.size());
  for (std::size_t c = 0; c < working.size(); ++c)
    models[c] = detail::geometric_model_for(working[c]);
  std::vector<std::array<double, 3>> corner_distance(labels.size());
  for (std::uint32_t f = 0; f < labels.size(); ++f) {
    const detail::GeometricModel* model = models[labels[f]].get();
    if (!model || !single_triangle(f)) continue;
    const Triangle corners = graph.corners(first_triangle[f]);
    double gradient[detail::kMaxParameters];
    for (int k = 0; k < 3; ++k)
      corner_distance[f][k] = model->residual(graph.position(corners[k]), gradient);
  }
  std::vector<std::vector<double>> second_differences(working.size());
  for (const DualEdge& edge : graph.edges()) {
    const std::uint32_t c = labels[edge.first];
    if (labels[edge.second] != c || !models[c] || !single_triangle(edge.first) ||
        !single_triangle(edge.second))
      continue;
    const Triangle one = graph.corners(first_triangle[edge.first]);
    const Triangle two = graph.corners(first_triangle[edge.second]);
    // s_c + s_d - s_a - s_b, c and d the corners of each triangle that the other lacks.
    double sum = 0;
    int apart = 0;
    for (int k = 0; k < 3; ++k) {
      const bool one_apart = std::find(two.begin(), two.end(), one[k]) == two.end();
      const bool two_apart = std::find(one.begin(), one.end(), two[k]) == one.end();
      sum += one_apart ? corner_distance[edge.first][k] : -corner_distance[edge.first][k];
      if (two_apart) sum += corner_distance[edge.second][k];
      apart += one_apart + two_apart;
    }
    if (apart == 2) second_differences[c].push_back(std::abs(sum));
  }
  std::vector<double> noise(working.size(), 0);
  for (std::size_t c = 0; c < noise.size(); ++c) {
    std::vector<double>& d = second_differences[c];
    if (d.empty()) continue;
    const auto middle = d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2);
    std::nth_element(d.begin(), middle, d.end());
    noise[c] = *middle / (0.6745 * 2);
  }
  return noise;
}

// face_error of f (given: `error`) and of the faces sharing an edge with it, summed.
double pooled_error(const Hierarchy& hierarchy, std::uint32_t f, double error,
                    const Primitive& working, const Adjacency& adjacency,
                    const std::vector<std::uint32_t>& first_triangle) {
  for (std::uint32_t i = adjacency.offset[f]; i < adjacency.offset[f + 1]; ++i)
    error += face_error(hierarchy, adjacency.neighbour[i], working, first_triangle);
  return error;
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

// Chooses again the type of each cluster flagged in `changed`, on the faces it has now: the tree
// chose it on the faces of the cluster's node, and a cluster that gained or lost faces may fit
// another type better (a noisy chamfer merged with a few faces of the corner it bevels is typed a
// sphere, whose arc bends towards the corner; given back its true faces, it fits its cone
// better). The hierarchy's rule (ModelSelector, over the corners, with the type penalties)
// proposes a type; it replaces the cluster's own only if it also fits the faces better, by the
// same integral as the moves and with the same penalties, than the cluster's own type does (the
// better of that type's algebraic fit to the same faces and the cluster's last primitive): the
// corners of a CAD fan and of one ring of the fillet beyond it lie exactly on a sphere, which
// misses the flat fan's triangles by far; and a cylinder's algebraic axis is a heuristic, which
// its last, geometric fit has refined (compared by its algebraic fit alone, bunny00's refined
// level at K = 40 lost 0.8% of RMS instead of gaining 1.1%). Where the type changes, `start`
// (input units) becomes the proposed fit. Each cluster on its own: the same result for any
// thread count.
void choose_types_again(const Hierarchy& hierarchy, const std::vector<std::uint32_t>& labels,
                        const std::vector<char>& changed,
                        const std::vector<std::uint32_t>& first_triangle, unsigned threads,
                        std::vector<Primitive>& start) {
  const DualGraph& graph = hierarchy.graph();
  const HierarchyOptions& options = hierarchy.options();
  if (options.primitives.size() < 2) return;  // nothing to choose from
  const detail::ModelSelector selector(options);
  const auto k = static_cast<std::uint32_t>(changed.size());
  const detail::ClusterTriangles triangles(hierarchy.mesh(), labels, k);
  // The mesh edges inside each changed cluster, summed in the dual graph's order.
  std::vector<EdgeStats> inner_edges(k);
  for (const DualEdge& e : graph.edges())
    if (labels[e.first] == labels[e.second] && changed[labels[e.first]])
      inner_edges[labels[e.first]] += e.shared;
  std::vector<std::uint32_t> clusters;
  for (std::uint32_t c = 0; c < k; ++c)
    if (changed[c]) clusters.push_back(c);
  const auto penalty = [&](PrimitiveType t) { return options.type_penalty[static_cast<int>(t)]; };
  threads = detail::thread_count(threads);
  std::vector<ClusterStats> face(threads);
  std::vector<FaceCorners> corners(threads);
  detail::parallel_for_threads(clusters.size(), threads, [&](std::size_t i, unsigned thread) {
    const std::uint32_t c = clusters[i];
    // Its faces, ascending: a face's triangles are consecutive.
    std::vector<std::uint32_t> members;
    for (const std::uint32_t t : triangles.of(c))
      if (const std::uint32_t f = hierarchy.mesh().face_of_triangle[t]; first_triangle[f] == t)
        members.push_back(f);
    // The moments are summed corner by corner about the first face's centroid, inside the
    // cluster, rather than translating every face's own moments.
    ClusterStats stats;
    for (const std::uint32_t f : members) {
      // A face of more than FaceCorners::kMaxTriangles triangles by its moments.
      if (graph.face_corners(f, corners[thread])) {
        if (f == members.front()) stats.moments = Moments(corners[thread].centroid);
        stats.add(corners[thread]);
        if (!selector.needs_samples()) continue;
        graph.face_stats(f, face[thread], true, 2);
        stats.samples.merge(face[thread].samples);
      } else {
        graph.face_stats(f, face[thread], selector.needs_samples(), 4);
        if (f == members.front()) stats.moments = Moments(face[thread].moments.origin());
        stats.merge(face[thread], EdgeStats{});
      }
    }
    stats.edges += inner_edges[c];
    const ClusterStats centred = stats.centred();
    const ClusterView cluster(centred);
    // Working frame: the proposed fit and the cluster's own type fitted to the same faces.
    const Primitive chosen = selector.select(cluster).fit.primitive;
    if (chosen.type == start[c].type) return;
    const PrimitiveFit own_fit = fitter_for(start[c].type).fit(cluster);
    const Primitive last = detail::to_working(graph.frame(), start[c]);
    double chosen_error = 0, own_error = 0, last_error = 0;
    for (const std::uint32_t f : members) {
      chosen_error += face_error(hierarchy, f, chosen, first_triangle);
      if (own_fit.valid) own_error += face_error(hierarchy, f, own_fit.primitive, first_triangle);
      last_error += face_error(hierarchy, f, last, first_triangle);
    }
    if (!own_fit.valid || last_error < own_error) own_error = last_error;
    if (chosen_error * penalty(chosen.type) < own_error * penalty(start[c].type))
      start[c] = graph.frame().to_input(chosen);
  });
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
  if (!(options.pooling_gap >= 0) || !std::isfinite(options.pooling_gap))
    throw InvalidInputError("refine_boundaries: the pooling gap must be a non-negative number");
  const Adjacency adjacency(hierarchy.graph());
  const std::vector<std::uint32_t> first_triangle = detail::first_triangles(mesh);

  RefinedLevel result;
  result.segmentation = segmentation;
  std::vector<std::uint32_t>& labels = result.segmentation.labels;
  result.reports = describe_clusters(hierarchy, result.segmentation, options.describe);
  const std::vector<std::uint32_t> initial_components = Components(adjacency, labels, k).count;
  std::vector<std::uint32_t> sizes(k, 0);
  for (std::uint32_t label : labels) ++sizes[label];
  const double cut_error = total_squared_error(hierarchy, labels, result.reports);

  // The noise is the data's: estimated once, on the cut (a fifth of the passes' time otherwise).
  const std::vector<double> noise =
      options.pooling_gap > 0
          ? cluster_noise(hierarchy, labels, working_primitives(hierarchy, result.reports),
                          first_triangle)
          : std::vector<double>(k, 0.0);
  for (std::uint32_t pass = 0; pass < options.max_passes; ++pass) {
    const std::vector<Primitive> working = working_primitives(hierarchy, result.reports);
    // Decide every move against the labels at the start of the pass.
    std::vector<std::uint32_t> target(f_count, kNone);
    std::vector<std::uint32_t> leaving(k, 0);
    for (std::uint32_t f = 0; f < f_count; ++f) {
      const std::uint32_t own = labels[f];
      double own_error = -1, own_pooled = -1, area = 0;
      double best_ratio = std::numeric_limits<double>::infinity();
      std::uint32_t best = kNone;
      for (std::uint32_t i = adjacency.offset[f]; i < adjacency.offset[f + 1]; ++i) {
        const std::uint32_t other = labels[adjacency.neighbour[i]];
        if (other == own || other == best) continue;
        if (own_error < 0) {
          own_error = face_error(hierarchy, f, working[own], first_triangle);
          area = face_area(hierarchy, f, first_triangle);
        }
        const double error = face_error(hierarchy, f, working[other], first_triangle);
        double ratio = error / own_error;
        // Nearer the other primitive by less than the clusters' noise, the face alone cannot
        // tell: its neighbours' errors join the decision (only ever towards a nearer primitive).
        if (error < own_error && std::sqrt(own_error / area) - std::sqrt(error / area) <
                                     options.pooling_gap * std::max(noise[own], noise[other])) {
          if (own_pooled < 0)
            own_pooled =
                pooled_error(hierarchy, f, own_error, working[own], adjacency, first_triangle);
          ratio = pooled_error(hierarchy, f, error, working[other], adjacency, first_triangle) /
                  own_pooled;
        }
        if (ratio < best_ratio || (ratio == best_ratio && other < best))
          best_ratio = ratio, best = other;
      }
      if (best != kNone && best_ratio < options.improvement) target[f] = best;
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
    // Each cluster's fit starts from its last one, or from another type that fits its faces
    // better now.
    std::vector<Primitive> start(k);
    for (std::uint32_t c = 0; c < k; ++c) start[c] = result.reports[c].primitive;
    std::vector<char> changed(k, 0);
    for (std::uint32_t f : moves) changed[origin[f]] = changed[labels[f]] = 1;
    choose_types_again(hierarchy, labels, changed, first_triangle, options.describe.threads, start);
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
