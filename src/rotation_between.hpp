#pragma once
// The shortest rotation taking one direction onto another.
//
// Eigen's Quaternion::FromTwoVectors computes the same (this is its formula where the directions
// are not opposite), but for opposite ones it finds the axis with a JacobiSVD, whose instantiation
// took a quarter of the compile time of the file that used it (regularity/directions.cpp, g++ -O3:
// 59 s with it, 44 s without; session 58). Here opposite directions turn about
// a fixed axis orthogonal to the first, which is as good: every such axis gives a half turn.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "orthonormal_pair.hpp"

namespace primseg::detail {

/// The unit quaternion of the smallest rotation that turns the direction of `from` onto that of
/// `to` (both non-zero, any length), to a few ulps over 1 + cos θ (the cross product that gives
/// its axis has length sin θ). When they are opposite (cosine below −1 + 1e-12), a half turn
/// about orthonormal_pair(from).first.
inline Eigen::Quaterniond rotation_between(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  const Eigen::Vector3d v0 = from.normalized(), v1 = to.normalized();
  const double cosine = v1.dot(v0);
  Eigen::Quaterniond rotation;
  if (cosine < -1 + 1e-12) {
    const double w2 = std::max(0.5 * (1 + cosine), 0.0);
    rotation.w() = std::sqrt(w2);
    rotation.vec() = orthonormal_pair(v0).first * std::sqrt(1 - w2);
    return rotation;
  }
  const double s = std::sqrt((1 + cosine) * 2);
  rotation.vec() = v0.cross(v1) * (1 / s);
  rotation.w() = s * 0.5;
  return rotation;
}

}  // namespace primseg::detail
