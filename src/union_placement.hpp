#pragma once
// Where the union of two disjoint weighted point sets sits relative to its parts: what
// ClusterView and FaceCorners::unite both compute, by the same operations, so that a pair of
// faces read by its corners and a view of the two faces agree bit for bit.

#include <Eigen/Core>

namespace primseg::detail {

struct UnionPlacement {
  Eigen::Vector3d centroid;  // the union's weighted centroid
  // Each part's centroid minus the union's: a point y_p about its part's centroid is
  // y_p + shift about the union's.
  Eigen::Vector3d shift_a = Eigen::Vector3d::Zero(), shift_b = Eigen::Vector3d::Zero();
  // What the union's second moment adds to the parts': w_a w_b / w · gap gapᵀ.
  Eigen::Matrix3d second_moment_gain = Eigen::Matrix3d::Zero();
};

// Parts of weights wa, wb (w = wa + wb) and centroids ca, cb. With no weight at all the union
// sits at ca.
inline UnionPlacement place_union(double wa, const Eigen::Vector3d& ca, double wb,
                                  const Eigen::Vector3d& cb, double w) {
  UnionPlacement placement;
  const Eigen::Vector3d gap = cb - ca;
  placement.centroid = ca;
  placement.shift_b = gap;
  if (w > 0) {
    // Exact when either weight is zero.
    placement.centroid = ca + (wb / w) * gap;
    placement.shift_a = -(wb / w) * gap;
    placement.shift_b = (wa / w) * gap;
    placement.second_moment_gain = (wa * wb / w) * gap * gap.transpose();
  }
  return placement;
}

}  // namespace primseg::detail
