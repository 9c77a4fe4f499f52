#pragma once
/// @file planar_triangulation.hpp
/// Triangulation of a planar domain bounded by closed polygonal loops (an outer loop and holes),
/// keeping every loop edge, for the planar patches of the shape generator.

#include <array>
#include <cstdint>
#include <vector>

namespace primseg::shape_detail {

struct Point2 {
  double x = 0, y = 0;
};

struct PlanarTriangulation {
  /// Vertices added inside the domain (none when no target edge length was given).
  std::vector<Point2> interior_points;
  /// Counter-clockwise triangles. Index i < (total loop vertex count) is the i-th vertex of the
  /// loops concatenated in order; larger indices are interior_points[i - loop vertex count].
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// Triangulates the region inside loops[0] and outside loops[1..] (even-odd rule). Loops are
/// closed (last vertex not repeated), simple, mutually disjoint, and either orientation.
///
/// With target_edge <= 0 no vertex is added: the result has (loop vertices + 2 holes - 2)
/// triangles, as a CAD exporter would produce. With target_edge > 0, vertices of a triangular
/// lattice of that spacing are added inside the domain, smoothed, and the result is the
/// constrained Delaunay triangulation; loop edges should then be at most target_edge long.
/// Throws std::logic_error if a loop edge cannot be recovered (self-intersecting loops).
PlanarTriangulation triangulate_planar_domain(const std::vector<std::vector<Point2>>& loops,
                                              double target_edge);

}  // namespace primseg::shape_detail
