#include "primseg/relations.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <span>
#include <string>

#include "cluster_numbering.hpp"
#include "cluster_triangles.hpp"
#include "parallel.hpp"
#include "primseg/error.hpp"
#include "primseg/geometric_fit.hpp"
#include "regularity.hpp"
#include "tree_nodes.hpp"
#include "triangle_corners.hpp"
#include "working_primitive.hpp"

namespace primseg {

std::string_view to_string(ClusterRelation::Kind kind) {
  switch (kind) {
    case ClusterRelation::Kind::Parallel:
      return "parallel";
    case ClusterRelation::Kind::Coaxial:
      return "coaxial";
    case ClusterRelation::Kind::Orthogonal:
      return "orthogonal";
    case ClusterRelation::Kind::EqualRadius:
      return "equal_radius";
    case ClusterRelation::Kind::Coplanar:
      return "coplanar";
    case ClusterRelation::Kind::Tangent:
      return "tangent";
    case ClusterRelation::Kind::Concentric:
      return "concentric";
  }
  return "unknown";
}

void validate(const RelationOptions& options) {
  auto refuse = [](const char* field, double value, const char* range) {
    throw InvalidInputError("relations: RelationOptions::" + std::string(field) + " is " +
                            std::to_string(value) + ", must be " + range);
  };
  if (!(options.significance > 0) || !std::isfinite(options.significance))
    refuse("significance", options.significance, "a positive number");
  if (!(options.max_angle_degrees > 0 && options.max_angle_degrees < 90))
    refuse("max_angle_degrees", options.max_angle_degrees, "in (0, 90) degrees");
  if (!(options.angle_tolerance_degrees >= 0 &&
        options.angle_tolerance_degrees < options.max_angle_degrees))
    refuse("angle_tolerance_degrees", options.angle_tolerance_degrees,
           "at least 0 and below max_angle_degrees");
  if (!(options.length_tolerance >= 0) || !std::isfinite(options.length_tolerance))
    refuse("length_tolerance", options.length_tolerance, "a finite number at least 0");
  if (!(options.max_radius_difference > 0 && options.max_radius_difference < 1))
    refuse("max_radius_difference", options.max_radius_difference, "in (0, 1)");
  if (!(options.outlier_threshold > 0) || !std::isfinite(options.outlier_threshold))
    refuse("outlier_threshold", options.outlier_threshold, "a positive number");
}

namespace {

constexpr std::uint32_t kUnseen = std::numeric_limits<std::uint32_t>::max();

/// Scratch space of gather_vertices(), indexed by mesh vertex.
struct VertexScratch {
  explicit VertexScratch(std::size_t vertex_count)
      : weight(vertex_count, 0.0), seen_in(vertex_count, kUnseen) {}
  std::vector<double> weight;
  std::vector<std::uint32_t> seen_in;  ///< the gathering that last saw the vertex
  std::uint32_t gathering = 0;
  std::vector<std::uint32_t> touched;
};

// A cluster's vertices once, in increasing order, weighted by the sum of their corners' weights
// in it (working frame), summed in the order of `triangles` (increasing): repeated corners would
// make the directions look better determined than they are. O(T_c + V_c log V_c).
void gather_vertices(const DualGraph& graph, std::span<const std::uint32_t> triangles,
                     VertexScratch& scratch, std::vector<Vec3>& points,
                     std::vector<double>& weights) {
  const std::uint32_t gathering = scratch.gathering++;
  scratch.touched.clear();
  for (const std::uint32_t t : triangles) {
    const Triangle vertices = graph.corners(t);
    const std::array<double, 3> corner_weights = graph.corner_weights(t);
    for (int j = 0; j < 3; ++j) {
      const std::uint32_t v = vertices[j];
      if (scratch.seen_in[v] != gathering) {
        scratch.seen_in[v] = gathering;
        scratch.weight[v] = 0;
        scratch.touched.push_back(v);
      }
      scratch.weight[v] += corner_weights[j];
    }
  }
  std::sort(scratch.touched.begin(), scratch.touched.end());
  points.clear();
  weights.clear();
  for (const std::uint32_t v : scratch.touched) {
    // Like the fits, a vertex of zero-area triangles only weighs nothing and is left out.
    if (!(scratch.weight[v] > 0)) continue;
    const Eigen::Vector3d& x = graph.position(v);
    points.push_back({x.x(), x.y(), x.z()});
    weights.push_back(scratch.weight[v]);
  }
}

// `options` for regularize(), which works in `hierarchy`'s working frame.
detail::RegularityOptions regularity_options(const RelationOptions& options,
                                             const Hierarchy& hierarchy) {
  detail::RegularityOptions regularity;
  regularity.significance = options.significance;
  regularity.max_angle_degrees = options.max_angle_degrees;
  regularity.angle_tolerance = options.angle_tolerance_degrees * std::numbers::pi / 180;
  regularity.length_tolerance = options.length_tolerance / hierarchy.graph().frame().scale();
  regularity.max_radius_difference = options.max_radius_difference;
  return regularity;
}

// The distance below which a point is an inlier whatever the median: round-off of the working
// frame, whose bounding box fits in [-1, 1]³.
double inlier_floor(const Hierarchy& hierarchy) {
  return 1e-12 * bounding_box_diagonal(hierarchy.mesh()) / hierarchy.graph().frame().scale();
}

// A refitted cluster's rms and max (working frame), measured on every corner of its triangles
// (increasing) as describe_clusters() measures them: from its reported primitive (`working` is
// the reported one's working-frame form), so with the same bits.
std::pair<double, double> measure(const DualGraph& graph, std::span<const std::uint32_t> triangles,
                                  const Primitive& working) {
  std::vector<Vec3> corners;
  std::vector<double> corner_weights;
  corners.reserve(3 * triangles.size());
  corner_weights.reserve(3 * triangles.size());
  for (const std::uint32_t t : triangles) detail::append_corners(graph, t, corners, corner_weights);
  GeometricFitOptions measure_only;
  measure_only.max_iterations = 0;
  const GeometricFit measured = fit_geometric(working, corners, corner_weights, measure_only);
  return {measured.rms, measured.max};
}

// The relations' members' new primitives (working frame, `primitives`) into their reports, with
// rms and max from `measure_cluster(c, the reported primitive in the working frame)`, and the
// relations' deviations into input units.
template <typename MeasureCluster>
void report_refitted(const WorkingFrame& frame, std::vector<ClusterRelation>& relations,
                     const std::vector<Primitive>& primitives,
                     const MeasureCluster& measure_cluster, std::vector<ClusterReport>& reports) {
  std::vector<bool> refitted(reports.size(), false);
  for (ClusterRelation& relation : relations) {
    for (const std::uint32_t c : relation.clusters) refitted[c] = true;
    for (const std::uint32_t c : relation.orthogonal_to) refitted[c] = true;
    if (relation.kind != ClusterRelation::Kind::Parallel &&
        relation.kind != ClusterRelation::Kind::Orthogonal)
      relation.deviation = std::ldexp(relation.deviation, frame.exponent);  // a length
  }
  for (std::size_t c = 0; c < reports.size(); ++c) {
    if (!refitted[c]) continue;
    reports[c].primitive = frame.to_input(primitives[c]);
    const auto [rms, max] = measure_cluster(c, detail::to_working(frame, reports[c].primitive));
    reports[c].rms = std::ldexp(rms, frame.exponent);
    reports[c].max = std::ldexp(max, frame.exponent);
  }
}

}  // namespace

std::vector<ClusterRelation> regularize_clusters(const Hierarchy& hierarchy,
                                                 const Segmentation& segmentation,
                                                 std::vector<ClusterReport>& reports,
                                                 const RelationOptions& options) {
  validate(options);
  const Mesh& mesh = hierarchy.mesh();
  const DualGraph& graph = hierarchy.graph();
  const std::uint32_t k = segmentation.cluster_count();
  if (segmentation.labels.size() != mesh.face_count() || reports.size() != k)
    throw InvalidInputError(
        "regularize_clusters: the segmentation or the reports do not match "
        "the mesh");
  for (const std::uint32_t label : segmentation.labels)
    if (label >= k)
      throw InvalidInputError("regularize_clusters: a label is not below the cluster count");

  const detail::ClusterTriangles clusters(mesh, segmentation.labels, k);
  VertexScratch scratch(mesh.vertex_count());
  std::vector<std::vector<Vec3>> points(k);
  std::vector<std::vector<double>> weights(k);
  for (std::uint32_t c = 0; c < k; ++c)
    gather_vertices(graph, clusters.of(c), scratch, points[c], weights[c]);

  std::vector<Primitive> primitives;
  primitives.reserve(k);
  for (const ClusterReport& report : reports)
    primitives.push_back(detail::to_working(graph.frame(), report.primitive));
  std::vector<ClusterRelation> relations =
      detail::regularize_inliers(primitives, points, weights, options.outlier_threshold,
                                 inlier_floor(hierarchy), regularity_options(options, hierarchy));
  report_refitted(
      graph.frame(), relations, primitives,
      [&](std::size_t c, const Primitive& working) {
        return measure(graph, clusters.of(c), working);
      },
      reports);
  return relations;
}

struct LevelRegularizer::Nodes {
  std::vector<std::uint32_t> ids;  ///< strictly increasing
  std::vector<ClusterReport> reports;
  std::vector<Primitive> working_primitives;  ///< each report's primitive, working frame
  std::vector<double> areas;                  ///< working-frame areas, as cut_by_count() sums them
  std::vector<std::uint32_t> lowest_faces;
  /// Each node's triangles in ascending order: rows of a compressed array.
  std::vector<std::size_t> triangle_offsets;
  std::vector<std::uint32_t> triangles;
  /// Each node's inlier vertices (working frame) and weights: rows of a compressed array.
  std::vector<std::size_t> inlier_offsets;
  std::vector<Vec3> inlier_points;
  std::vector<double> inlier_weights;

  /// A refitted node's rms and max (working frame) by its node index and primitive's bits:
  /// adjacent levels mostly refit the same members the same way (bunny00's 391 levels measure
  /// 48,678 fits, 19,713 of them different).
  using MeasureKey = std::array<std::uint64_t, 11>;
  std::mutex measured_mutex;
  std::map<MeasureKey, std::pair<double, double>> measured;

  std::span<const std::uint32_t> triangles_of(std::size_t i) const {
    return std::span<const std::uint32_t>(triangles).subspan(
        triangle_offsets[i], triangle_offsets[i + 1] - triangle_offsets[i]);
  }
};

LevelRegularizer::LevelRegularizer(const Hierarchy& hierarchy, std::span<const std::uint32_t> nodes,
                                   std::span<const ClusterReport> reports,
                                   const RelationOptions& options, unsigned threads)
    : hierarchy_(&hierarchy), options_(options), nodes_(std::make_unique<Nodes>()) {
  validate(options);
  if (reports.size() != nodes.size())
    throw InvalidInputError("LevelRegularizer: " + std::to_string(reports.size()) +
                            " reports for " + std::to_string(nodes.size()) + " nodes");
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    detail::check_cluster_node(hierarchy, nodes[i], "LevelRegularizer");
    if (i > 0 && nodes[i] <= nodes[i - 1])
      throw InvalidInputError("LevelRegularizer: the nodes are not strictly increasing");
  }
  Nodes& n = *nodes_;
  n.ids.assign(nodes.begin(), nodes.end());
  n.reports.assign(reports.begin(), reports.end());
  const DualGraph& graph = hierarchy.graph();
  const detail::LeafOrder leaves(hierarchy);
  n.triangle_offsets.assign(nodes.size() + 1, 0);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const std::uint32_t first = leaves.start[nodes[i]];
    std::size_t count = 0;
    for (std::uint32_t j = first; j < first + hierarchy.face_count(nodes[i]); ++j) {
      const std::uint32_t face = leaves.faces[j];
      count += graph.first_triangle(face + 1) - graph.first_triangle(face);
    }
    n.triangle_offsets[i + 1] = n.triangle_offsets[i] + count;
  }
  n.triangles.resize(n.triangle_offsets.back());
  n.working_primitives.resize(nodes.size());
  n.areas.assign(nodes.size(), 0.0);
  n.lowest_faces.resize(nodes.size());

  // Each node on its own, so the same for any thread count; the inliers are joined in node order.
  const unsigned thread_count = detail::thread_count(threads);
  std::vector<std::vector<Vec3>> points(nodes.size());
  std::vector<std::vector<double>> weights(nodes.size());
  std::vector<VertexScratch> scratches(thread_count,
                                       VertexScratch(hierarchy.mesh().vertex_count()));
  std::vector<std::vector<std::uint32_t>> faces(thread_count);
  std::vector<std::vector<Vec3>> all_points(thread_count);
  std::vector<std::vector<double>> all_weights(thread_count);
  const double floor = inlier_floor(hierarchy);
  detail::parallel_for_threads(nodes.size(), thread_count, [&](std::size_t i, unsigned thread) {
    leaves.ascending_faces(hierarchy, nodes[i], faces[thread]);
    n.lowest_faces[i] = faces[thread].front();
    std::size_t at = n.triangle_offsets[i];
    for (const std::uint32_t face : faces[thread])
      for (std::uint32_t t = graph.first_triangle(face); t < graph.first_triangle(face + 1); ++t) {
        n.triangles[at++] = t;
        n.areas[i] += graph.triangle_area(t);
      }
    n.working_primitives[i] = detail::to_working(graph.frame(), n.reports[i].primitive);
    gather_vertices(graph, n.triangles_of(i), scratches[thread], all_points[thread],
                    all_weights[thread]);
    if (!all_points[thread].empty())
      detail::keep_inliers(n.working_primitives[i], all_points[thread], all_weights[thread],
                           options.outlier_threshold, floor, points[i], weights[i]);
  });
  n.inlier_offsets.assign(nodes.size() + 1, 0);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    n.inlier_offsets[i + 1] = n.inlier_offsets[i] + points[i].size();
    n.inlier_points.insert(n.inlier_points.end(), points[i].begin(), points[i].end());
    n.inlier_weights.insert(n.inlier_weights.end(), weights[i].begin(), weights[i].end());
  }
}

LevelRegularizer::~LevelRegularizer() = default;
LevelRegularizer::LevelRegularizer(LevelRegularizer&&) noexcept = default;
LevelRegularizer& LevelRegularizer::operator=(LevelRegularizer&&) noexcept = default;

RegularizedLevel LevelRegularizer::level(std::uint32_t clusters) const {
  const Hierarchy& hierarchy = *hierarchy_;
  Nodes& n = *nodes_;
  std::vector<std::size_t> members;  // indices into n.ids
  for (const std::uint32_t node : detail::level_nodes(hierarchy, clusters)) {
    const auto at = std::lower_bound(n.ids.begin(), n.ids.end(), node);
    if (at == n.ids.end() || *at != node)
      throw InvalidInputError("LevelRegularizer: node " + std::to_string(node) + " of level " +
                              std::to_string(clusters) + " was not given");
    members.push_back(static_cast<std::size_t>(at - n.ids.begin()));
  }
  // Numbered as cut_by_count() numbers them: by decreasing area, ties by lowest face.
  detail::sort_into_label_order(
      members, [&](std::size_t i) { return n.areas[i]; },
      [&](std::size_t i) { return n.lowest_faces[i]; });

  RegularizedLevel result;
  const std::size_t k = members.size();
  result.nodes.reserve(k);
  result.reports.reserve(k);
  std::vector<Primitive> primitives;
  primitives.reserve(k);
  std::vector<std::vector<Vec3>> points(k);
  std::vector<std::vector<double>> weights(k);
  for (std::size_t c = 0; c < k; ++c) {
    const std::size_t i = members[c];
    result.nodes.push_back(n.ids[i]);
    result.reports.push_back(n.reports[i]);
    result.reports.back().id = static_cast<std::uint32_t>(c);
    primitives.push_back(n.working_primitives[i]);
    const auto first = static_cast<std::ptrdiff_t>(n.inlier_offsets[i]);
    const auto last = static_cast<std::ptrdiff_t>(n.inlier_offsets[i + 1]);
    points[c].assign(n.inlier_points.begin() + first, n.inlier_points.begin() + last);
    weights[c].assign(n.inlier_weights.begin() + first, n.inlier_weights.begin() + last);
  }
  result.relations = detail::regularize_kept(primitives, points, weights,
                                             regularity_options(options_, *hierarchy_));
  report_refitted(
      hierarchy.graph().frame(), result.relations, primitives,
      [&](std::size_t c, const Primitive& working) {
        Nodes::MeasureKey key{members[c], static_cast<std::uint64_t>(working.type)};
        const std::array<double, 9> values{
            working.point[0], working.point[1],     working.point[2],
            working.axis[0],  working.axis[1],      working.axis[2],
            working.radius,   working.minor_radius, working.half_angle};
        for (std::size_t v = 0; v < values.size(); ++v)
          key[2 + v] = std::bit_cast<std::uint64_t>(values[v]);
        {
          const std::lock_guard<std::mutex> lock(n.measured_mutex);
          if (const auto found = n.measured.find(key); found != n.measured.end())
            return found->second;
        }
        // Measured outside the lock: another thread measuring the same key gets the same bits.
        const std::pair<double, double> measured =
            measure(hierarchy.graph(), n.triangles_of(members[c]), working);
        const std::lock_guard<std::mutex> lock(n.measured_mutex);
        n.measured.emplace(key, measured);
        return measured;
      },
      result.reports);
  return result;
}

}  // namespace primseg
