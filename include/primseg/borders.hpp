#pragma once
/// @file borders.hpp
/// Where the clusters of a segmentation meet: each border as ordered curves of mesh vertices, its
/// length, and the angle the two fitted surfaces make across it. These are the feature curves of
/// reverse engineering: a box's edges at 90 degrees, a fillet's two borders at 0 (tangent), a
/// 45-degree chamfer's at 45; and the open boundary of a scan, cluster by cluster.

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "primseg/mesh.hpp"
#include "primseg/primitive.hpp"

namespace primseg {

/// ClusterBorder::second of a border along the mesh's open boundary.
inline constexpr std::uint32_t kMeshBoundary = std::numeric_limits<std::uint32_t>::max();

/// A chain of mesh vertices along a border, consecutive ones joined by one of its edges.
struct BorderCurve {
  /// Vertex indices in order along the curve, shape (n), n >= 2 (n >= 3 when closed).
  std::vector<std::uint32_t> vertices;
  /// The last vertex joins the first by an edge of the border (the first is not repeated).
  bool closed = false;
};

/// The mesh edges between two clusters, or between a cluster and the mesh's open boundary (edges
/// of one triangle only).
struct ClusterBorder {
  std::uint32_t first = 0;   ///< a cluster (label)
  std::uint32_t second = 0;  ///< a cluster above `first`, or kMeshBoundary
  std::uint32_t edge_count = 0;
  double length = 0;  ///< the edges' total length, input units
  /// Mean angle, in degrees in [0, 180], between the two clusters' primitives across the border,
  /// weighted by edge length. At each edge's midpoint each primitive's normal
  /// (Primitive::normal) is oriented like its cluster's triangle on the edge, the two triangles
  /// taken consistently oriented across the edge: so the angle is how far the surface turns
  /// there, whatever way the file orients its faces. 0 where the primitives meet tangentially,
  /// 90 at a box's edge. NaN along the mesh boundary, without primitives, and when the triangles
  /// of every edge have zero area.
  double angle = std::numeric_limits<double>::quiet_NaN();
  /// Its edges as curves, each edge in exactly one. A curve stops at an end of the border: a
  /// vertex where another border meets it (a corner: a third cluster or the mesh boundary), or
  /// where it does not go on through exactly two of its edges. A loop without an end is closed.
  /// Curves from ends come first, each starting at its lower-numbered end (closed when it comes
  /// back to the end it left), then the loops, each from its lowest edge.
  std::vector<BorderCurve> curves;
};

/// Every border of the clusters `face_labels` assigns, sorted by (first, second). Non-manifold
/// edges (k >= 3 triangles): two clusters share one when the dual graph links a triangle of each
/// across it (dual_graph.hpp: the triangles in index order, each linked to the next), the pairs
/// the hierarchy could merge there; so an edge is in at most k − 1 borders, not k². Degenerate
/// edges (both ends the same vertex) are left out; zero-length ones count. O(T log T).
/// - `face_labels`: the cluster of each input face, shape (F); any values but kMeshBoundary.
/// - `primitives`: the clusters' primitives, shape (K) with K above every label, input units; or
///   empty, and every angle is NaN.
/// Throws InvalidInputError when the shapes disagree or a label is out of range.
std::vector<ClusterBorder> cluster_borders(const Mesh& mesh,
                                           std::span<const std::uint32_t> face_labels,
                                           std::span<const Primitive> primitives = {});

}  // namespace primseg
