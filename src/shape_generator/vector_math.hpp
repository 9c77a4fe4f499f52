#pragma once
/// @file vector_math.hpp
/// Minimal Vec3 arithmetic for the shape generator, also used by the skeleton code and the glTF
/// writer (kept private to avoid clashing with helpers of other modules).

#include <cmath>
#include <span>
#include <vector>

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

/// Per vertex, the sum of its triangles' (b - a) x (c - a): twice their areas times their unit
/// normals, so that its direction is the area-weighted vertex normal. Zero for a vertex of no
/// triangle (or of no area). Shape (n).
inline std::vector<Vec3> area_weighted_normal_sums(std::span<const Vec3> positions,
                                                   std::span<const Triangle> triangles) {
  std::vector<Vec3> sums(positions.size(), Vec3{0, 0, 0});
  for (const Triangle& t : triangles) {
    const Vec3 &a = positions[t[0]], &b = positions[t[1]], &c = positions[t[2]];
    const Vec3 area_normal = cross(b - a, c - a);
    for (const std::uint32_t v : t) sums[v] = sums[v] + area_normal;
  }
  return sums;
}

}  // namespace primseg::shape_detail
