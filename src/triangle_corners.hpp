#pragma once
// A triangle's corners as weighted points of the working frame: what the reports' fits and
// measures (describe_clusters, regularize_clusters) read, in one place.

#include <array>
#include <cstdint>
#include <vector>

#include "primseg/dual_graph.hpp"

namespace primseg::detail {

/// Appends the three corners of triangle t (working frame) and their weights, in corners(t) order.
inline void append_corners(const DualGraph& graph, std::uint32_t t, std::vector<Vec3>& points,
                           std::vector<double>& weights) {
  const Triangle corners = graph.corners(t);
  const std::array<double, 3> w = graph.corner_weights(t);
  for (int corner = 0; corner < 3; ++corner) {
    const Eigen::Vector3d& x = graph.position(corners[corner]);
    points.push_back({x.x(), x.y(), x.z()});
    weights.push_back(w[corner]);
  }
}

}  // namespace primseg::detail
