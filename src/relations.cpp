#include "primseg/relations.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "primseg/error.hpp"
#include "primseg/geometric_fit.hpp"
#include "regularity.hpp"
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
  if (!(options.max_radius_difference > 0 && options.max_radius_difference < 1))
    refuse("max_radius_difference", options.max_radius_difference, "in (0, 1)");
  if (!(options.outlier_threshold > 0) || !std::isfinite(options.outlier_threshold))
    refuse("outlier_threshold", options.outlier_threshold, "a positive number");
}

std::vector<ClusterRelation> regularize_clusters(const Hierarchy& hierarchy,
                                                 const Segmentation& segmentation,
                                                 std::vector<ClusterReport>& reports,
                                                 const RelationOptions& options) {
  validate(options);
  const Mesh& mesh = hierarchy.mesh();
  const DualGraph& graph = hierarchy.graph();
  const WorkingFrame& frame = graph.frame();
  const std::uint32_t k = segmentation.cluster_count();
  if (segmentation.labels.size() != mesh.face_count() || reports.size() != k)
    throw InvalidInputError(
        "regularize_clusters: the segmentation or the reports do not match "
        "the mesh");
  for (const std::uint32_t label : segmentation.labels)
    if (label >= k)
      throw InvalidInputError("regularize_clusters: a label is not below the cluster count");

  // Each cluster's vertices once, in increasing order, weighted by the sum of their corners'
  // weights in it (working frame), summed in increasing triangle order: repeated corners would
  // make the directions look better determined than they are. The triangles are grouped by
  // cluster (counting sort) and each vertex's weight gathered in a vertex-indexed scratch entry,
  // O(T + Σ V_c log V_c).
  std::vector<std::uint32_t> triangle_offsets(static_cast<std::size_t>(k) + 1, 0);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t)
    ++triangle_offsets[segmentation.labels[mesh.face_of_triangle[t]] + 1];
  for (std::uint32_t c = 0; c < k; ++c) triangle_offsets[c + 1] += triangle_offsets[c];
  std::vector<std::uint32_t> triangles_by_cluster(mesh.triangle_count());
  {
    std::vector<std::uint32_t> next(triangle_offsets.begin(), triangle_offsets.end() - 1);
    for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t)
      triangles_by_cluster[next[segmentation.labels[mesh.face_of_triangle[t]]]++] = t;
  }
  constexpr std::uint32_t kUnseen = std::numeric_limits<std::uint32_t>::max();
  std::vector<double> vertex_weight(mesh.vertex_count(), 0.0);
  std::vector<std::uint32_t> seen_in(mesh.vertex_count(), kUnseen), touched;
  std::vector<std::vector<Vec3>> points(k);
  std::vector<std::vector<double>> weights(k);
  for (std::uint32_t c = 0; c < k; ++c) {
    touched.clear();
    for (std::uint32_t i = triangle_offsets[c]; i < triangle_offsets[c + 1]; ++i) {
      const std::uint32_t t = triangles_by_cluster[i];
      const Triangle vertices = graph.corners(t);
      const std::array<double, 3> corner_weights = graph.corner_weights(t);
      for (int j = 0; j < 3; ++j) {
        const std::uint32_t v = vertices[j];
        if (seen_in[v] != c) {
          seen_in[v] = c;
          vertex_weight[v] = 0;
          touched.push_back(v);
        }
        vertex_weight[v] += corner_weights[j];
      }
    }
    std::sort(touched.begin(), touched.end());
    for (const std::uint32_t v : touched) {
      // Like the fits, a vertex of zero-area triangles only weighs nothing and is left out.
      if (!(vertex_weight[v] > 0)) continue;
      const Eigen::Vector3d& x = graph.position(v);
      points[c].push_back({x.x(), x.y(), x.z()});
      weights[c].push_back(vertex_weight[v]);
    }
  }

  std::vector<Primitive> primitives;
  primitives.reserve(k);
  for (const ClusterReport& report : reports)
    primitives.push_back(detail::to_working(frame, report.primitive));
  detail::RegularityOptions regularity;
  regularity.significance = options.significance;
  regularity.max_angle_degrees = options.max_angle_degrees;
  regularity.max_radius_difference = options.max_radius_difference;
  // The working frame's bounding box fits in [-1, 1]³.
  const double floor = 1e-12 * bounding_box_diagonal(mesh) / frame.scale();
  std::vector<ClusterRelation> relations = detail::regularize_inliers(
      primitives, points, weights, options.outlier_threshold, floor, regularity);

  // The members' new primitives, measured on every corner as describe_clusters() measures.
  std::vector<bool> refitted(k, false);
  for (const ClusterRelation& relation : relations) {
    for (const std::uint32_t c : relation.clusters) refitted[c] = true;
    for (const std::uint32_t c : relation.orthogonal_to) refitted[c] = true;
  }
  GeometricFitOptions measure_only;
  measure_only.max_iterations = 0;
  std::vector<Vec3> corners;
  std::vector<double> corner_weights;
  for (std::uint32_t c = 0; c < k; ++c) {
    if (!refitted[c]) continue;
    corners.clear();
    corner_weights.clear();
    for (std::uint32_t i = triangle_offsets[c]; i < triangle_offsets[c + 1]; ++i)
      detail::append_corners(graph, triangles_by_cluster[i], corners, corner_weights);
    // From the reported primitive, as describe_clusters() would measure it: the same bits.
    reports[c].primitive = frame.to_input(primitives[c]);
    const GeometricFit measured = fit_geometric(detail::to_working(frame, reports[c].primitive),
                                                corners, corner_weights, measure_only);
    reports[c].rms = std::ldexp(measured.rms, frame.exponent);
    reports[c].max = std::ldexp(measured.max, frame.exponent);
  }
  return relations;
}

}  // namespace primseg
