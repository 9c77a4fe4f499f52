#pragma once
/// @file edge_sides.hpp
/// The mesh's edges with the clusters on each side: what cluster borders (borders.hpp), skeleton
/// joints (skeleton.hpp) and the border lines of pictures (render.hpp) are made of.

#include <compare>
#include <cstdint>
#include <span>
#include <vector>

#include "primseg/mesh.hpp"

namespace primseg::detail {

/// Cluster of each triangle, shape (T), from the cluster of each input face (shape (F)).
std::vector<std::uint32_t> triangle_labels(const Mesh& mesh,
                                           std::span<const std::uint32_t> face_labels);

/// One triangle on one mesh edge.
struct EdgeSide {
  std::uint32_t low = 0, high = 0;  ///< the edge's vertices, low < high
  std::uint32_t label = 0;          ///< the triangle's cluster
  std::uint32_t triangle = 0;
  // NOLINTNEXTLINE(modernize-use-nullptr): clang-tidy 14 misreads the defaulted <=>.
  auto operator<=>(const EdgeSide&) const = default;
};

/// Every side of every edge of the triangles (edges between equal vertex indices left out), sorted
/// by (low, high, label, triangle): the sides of one edge are consecutive. `triangle_labels` has
/// shape (T).
std::vector<EdgeSide> edge_sides(const Mesh& mesh, std::span<const std::uint32_t> triangle_labels);

/// The end of the run of sides of the edge at `begin` (sides sorted as edge_sides() returns them).
std::size_t edge_end(std::span<const EdgeSide> sides, std::size_t begin);

/// Two sides of one edge whose triangles the dual graph links, of different clusters: `first` has
/// the lower label.
struct ClusterLink {
  EdgeSide first, second;
};

/// Appends to `links` the links across one edge between triangles of different clusters, as the
/// dual graph makes them (dual_graph.hpp): across a manifold edge its two triangles; on any other
/// edge each triangle and the next in index order. So two clusters meet on an edge exactly when
/// the hierarchy could merge them across it. Each pair of clusters once, by its first link in
/// that order, sorted by (first label, second label): at most k − 1 links for k sides, never k².
/// `edge` is the run of sides of one edge (edge_sides() order); `scratch` is reused storage.
void append_cluster_links(std::span<const EdgeSide> edge, std::vector<EdgeSide>& scratch,
                          std::vector<ClusterLink>& links);

}  // namespace primseg::detail
