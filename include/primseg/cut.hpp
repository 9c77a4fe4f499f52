#pragma once
/// @file cut.hpp
/// Levels of a hierarchy: per-face labels and per-cluster primitives, each cut in O(F).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "primseg/geometric_fit.hpp"
#include "primseg/hierarchy.hpp"

namespace primseg {

/// A level of the hierarchy.
struct Segmentation {
  /// Cluster of each input face, 0..K-1, shape (F). Clusters are numbered by decreasing area,
  /// ties by their lowest face index.
  std::vector<std::uint32_t> labels;
  /// Tree node of each cluster, shape (K).
  std::vector<std::uint32_t> nodes;
  std::uint32_t cluster_count() const { return static_cast<std::uint32_t>(nodes.size()); }
};

/// The level with `clusters` clusters: the first F − K real merges applied. Trailing merges are
/// never applied, so K below the number of components C gives C clusters. Throws
/// InvalidInputError unless 1 <= clusters <= F.
Segmentation cut_by_count(const Hierarchy& hierarchy, std::uint32_t clusters);

/// Walking top-down from each component's root, a node is kept whole when its RMS estimate
/// (Hierarchy::rms_estimate, input units) is at most `tolerance`, else its children are visited;
/// leaves are always kept. Throws InvalidInputError for a negative or non-finite tolerance.
Segmentation cut_by_tolerance(const Hierarchy& hierarchy, double tolerance);

/// What a user wants to know about one cluster of a cut.
struct ClusterReport {
  std::uint32_t id = 0;    ///< its label
  std::uint32_t node = 0;  ///< its tree node (after boundary refinement: the node it grew from)
  /// Fitted primitive, input units: the geometric fit (geometric_fit.hpp) started from
  /// `algebraic`, unless DescribeOptions::geometric_fit is off.
  Primitive primitive;
  Primitive algebraic;  ///< the fit the reported one started from (the tree's), input units
  double area = 0;      ///< input units²
  std::uint32_t face_count = 0;
  /// Exact weighted RMS Euclidean distance of the cluster's vertices to `primitive` (each
  /// triangle corner weighted as in the hierarchy), input units.
  double rms = 0;
  /// Largest Euclidean distance to `primitive` of a cluster vertex of positive weight, input
  /// units. Under area weights the corners of zero-area triangles weigh nothing and are left out
  /// (0 for a cluster of zero-area triangles only), as they are from the fit and from `rms`.
  double max = 0;
};

/// Options of describe_clusters().
struct DescribeOptions {
  /// Refine each primitive by a geometric least-squares fit to the cluster's vertices
  /// (fit_geometric); off: report the starting primitive as it is.
  bool geometric_fit = true;
  GeometricFitOptions fit;
  /// Threads over the clusters (0: all hardware threads); the reports are the same for any.
  unsigned threads = 0;
};

/// Reports of every cluster of a cut, in label order, each started from its node's primitive.
/// O(F) per geometric fit iteration.
std::vector<ClusterReport> describe_clusters(const Hierarchy& hierarchy,
                                             const Segmentation& segmentation,
                                             const DescribeOptions& options = {});

/// The same for clusters that need not be tree nodes (after boundary refinement): `start` holds
/// the primitive each cluster's fit starts from (input units), shape (K).
std::vector<ClusterReport> describe_clusters(const Hierarchy& hierarchy,
                                             const Segmentation& segmentation,
                                             const std::vector<Primitive>& start,
                                             const DescribeOptions& options = {});

/// The primitive of each report, in order, shape (K): what cluster_borders() and
/// extract_skeleton() take beside the labels.
std::vector<Primitive> cluster_primitives(std::span<const ClusterReport> reports);

/// Reports of tree nodes, in the order given, each the report describe_clusters makes when the
/// node is a cluster of a cut (same primitive, rms, max and area, bit for bit): what `primseg
/// view` carries for the levels a user may click. `id` is the node's index in `nodes`. O(size of
/// the node) per node and geometric fit iteration, plus O(F) once. Throws InvalidInputError for
/// a node outside the tree or a trailing merge (which joins components and has no fit).
std::vector<ClusterReport> describe_nodes(const Hierarchy& hierarchy,
                                          std::span<const std::uint32_t> nodes,
                                          const DescribeOptions& options = {});

/// The whole tree as SciPy's linkage matrix, shape (F − 1, 4): children node ids, height, face
/// count; row i creates node F + i (Hierarchy::merges() order, trailing merges last).
/// The heights are the merge costs made strictly increasing: a merge that costs no more than the
/// one before it (greedy costs can drop after a merge) gets the next double above the previous
/// height. So the matrix is monotonic, and scipy.cluster.hierarchy's cut_tree and fcluster,
/// which order merges by height, apply them in the tree's order and give cut_by_count's levels.
/// Heights are working-frame costs (weight × length², see Merge::cost), for ordering only.
std::vector<std::array<double, 4>> scipy_linkage(const Hierarchy& hierarchy);

}  // namespace primseg
