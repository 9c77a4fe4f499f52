#pragma once
// The frame of the plane orthogonal to an axis, the same one everywhere (cylinder fits, the
// geometric fit's models, the relations between primitives), so that results agree bit for bit.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <utility>

namespace primseg::detail {

/// A unit vector u orthogonal to the unit vector a (a × the coordinate axis least aligned with
/// a), and v = a × u completing a right-handed frame.
inline std::pair<Eigen::Vector3d, Eigen::Vector3d> orthonormal_pair(const Eigen::Vector3d& a) {
  Eigen::Index least;
  a.cwiseAbs().minCoeff(&least);
  const Eigen::Vector3d u = a.cross(Eigen::Vector3d::Unit(least)).normalized();
  return {u, a.cross(u)};
}

}  // namespace primseg::detail
