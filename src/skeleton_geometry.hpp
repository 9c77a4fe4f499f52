#pragma once
/// @file skeleton_geometry.hpp
/// Vector helpers shared by the skeleton and skinning code (the Vec3 arithmetic is the shape
/// generator's).

#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "edge_sides.hpp"
#include "primseg/mesh.hpp"
#include "primseg/skeleton.hpp"
#include "shape_generator/vector_math.hpp"

namespace primseg::skeleton_detail {

using namespace shape_detail;  // Vec3 +, -, scalar *, dot, cross, norm, normalized

/// The unit direction flipped so that its largest-magnitude component is positive.
Vec3 canonical_direction(const Vec3& unit);

/// Distance from x to the line through `point` with unit direction `axis`.
double distance_to_line(const Vec3& x, const Vec3& point, const Vec3& axis);

/// The edges shared by two clusters.
struct ClusterPairBoundary {
  std::uint32_t first = 0, second = 0;  ///< clusters, first < second
  double length = 0;                    ///< total edge length
  Vec3 weighted_midpoints{0, 0, 0};     ///< Σ edge length × edge midpoint
  std::vector<std::uint32_t> vertices;  ///< vertices of those edges, increasing
};

using detail::triangle_labels;

/// Throws InvalidInputError, its message starting with `caller`, unless `skeleton` was made for
/// `mesh`: one face label per face, each naming one of its bones.
void check_face_labels(const Mesh& mesh, const Skeleton& skeleton, std::string_view caller);

/// Every pair of clusters that share a mesh edge (an edge of triangles of both), sorted by
/// (first, second). On a non-manifold edge, the pairs the dual graph links across it
/// (edge_sides.hpp: append_cluster_links).
std::vector<ClusterPairBoundary> cluster_pair_boundaries(
    const Mesh& mesh, std::span<const std::uint32_t> triangle_labels);

}  // namespace primseg::skeleton_detail
