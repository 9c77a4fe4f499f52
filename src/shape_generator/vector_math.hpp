#pragma once
/// @file vector_math.hpp
/// Minimal Vec3 arithmetic for the shape generator (kept private to avoid clashing with helpers
/// of other modules).

#include <cmath>

#include "primseg/mesh.hpp"

namespace primseg::shape_detail {

inline Vec3 operator+(const Vec3& a, const Vec3& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
inline Vec3 operator-(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline Vec3 operator*(double s, const Vec3& a) {
  return {s * a[0], s * a[1], s * a[2]};
}
inline double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
inline Vec3 normalized(const Vec3& a) {
  return (1.0 / norm(a)) * a;
}

/// A unit vector perpendicular to the unit vector n (any one; deterministic).
inline Vec3 any_perpendicular(const Vec3& n) {
  // Crossing with the coordinate axis least aligned with n keeps the result well conditioned.
  const double ax = std::abs(n[0]), ay = std::abs(n[1]), az = std::abs(n[2]);
  const Vec3 helper =
      (ax <= ay && ax <= az) ? Vec3{1, 0, 0} : (ay <= az ? Vec3{0, 1, 0} : Vec3{0, 0, 1});
  return normalized(cross(n, helper));
}

}  // namespace primseg::shape_detail
