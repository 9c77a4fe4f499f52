#pragma once
/// @file eigen_conversions.hpp
/// The public Vec3 (std::array<double, 3>) to Eigen's vectors and back, for the library's
/// internals.

#include <Eigen/Core>

#include "primseg/mesh.hpp"

namespace primseg::detail {

inline Eigen::Vector3d to_eigen(const Vec3& v) {
  return {v[0], v[1], v[2]};
}

inline Vec3 to_vec3(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

}  // namespace primseg::detail
