#pragma once
/// @file refine.hpp
/// Boundary refinement of a cut: faces on the border between two clusters move to the adjacent
/// cluster whose primitive fits them better, primitives are refitted, and this repeats. Greedy
/// merging decides a border once, early, from small clusters; the final primitives know better.
/// Only border faces are examined (the paper found full Lloyd iterations costly for little
/// gain), and the moves that would split a cluster are undone, so clusters stay connected.

#include <cstdint>
#include <vector>

#include "primseg/cut.hpp"

namespace primseg {

/// Options of refine_boundaries().
struct BoundaryRefinementOptions {
  /// Passes at most; each examines every border face once, then refits. Stops earlier when a
  /// pass moves nothing.
  std::uint32_t max_passes = 5;
  /// A face moves only if its error to the other primitive is below this fraction of its error
  /// to its own (no churn between primitives that fit it equally well).
  double improvement = 0.5;
  /// How the primitives are refitted and reported.
  DescribeOptions describe;
};

/// A refined level.
struct RefinedLevel {
  /// Labels after the moves, same cluster numbering as the input; `nodes` are the tree nodes
  /// the clusters grew from.
  Segmentation segmentation;
  /// The final clusters, each refitted (describe_clusters of the final labels).
  std::vector<ClusterReport> reports;
  std::uint32_t passes = 0;       ///< passes that moved at least one face
  std::uint32_t moved_faces = 0;  ///< moves made over all passes (a face may move twice)
};

/// Refines the borders of a cut. A face's error to a primitive is the integral of the squared
/// distance over its triangles (three-point edge-midpoint rule: exact for planes). Moves are
/// decided for all border faces against the labels at the start of the pass, no cluster loses
/// all its faces, and every cluster keeps its number of connected components: where the moves
/// of a pass would cut a piece off a connected cluster, its largest piece stays (ties: the one
/// with the lowest face) and the moves next to the others are undone, layer by layer, until
/// they are reconnected; the cluster's other moves stand. A pass that leaves the clusters'
/// total error over their corners (Σ w d², what ClusterReport::rms measures) more than 5% above
/// the cut's is undone and ends the refinement: over its flat triangles, a face of an exact but
/// coarsely tessellated cylinder can look closer to a plane it meets at a shallow crease.
/// Deterministic. Throws InvalidInputError for a segmentation of another mesh or a non-positive
/// improvement factor.
RefinedLevel refine_boundaries(const Hierarchy& hierarchy, const Segmentation& segmentation,
                               const BoundaryRefinementOptions& options = {});

}  // namespace primseg
