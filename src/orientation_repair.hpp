#pragma once
// Putting back vertices whose new positions invert triangles (denoising's ensemble mean).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <vector>

#include "eigen_conversions.hpp"
#include "primseg/mesh.hpp"

namespace primseg {

/// True when the triangle (a, b, c) faces against `reference` (its normal in the input, any
/// length); a triangle of zero area does not.
inline bool turned_over(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                        const Eigen::Vector3d& c, const Vec3& reference) {
  return (b - a).cross(c - a).dot(detail::to_eigen(reference)) < 0;
}

/// Gives every vertex of a triangle that `positions` turns over (turned_over() against
/// `reference_normals[t]`, shape (T)) its position in `safe`, pass after pass, until none is.
/// `safe` must invert none: then each pass puts back at least one vertex, and at worst all end at
/// `safe`. `positions` and `safe` have one entry per vertex. Returns how many vertices were put
/// back.
std::uint32_t revert_inverted_triangles(std::span<Vec3> positions, std::span<const Vec3> safe,
                                        const std::vector<Triangle>& triangles,
                                        std::span<const Vec3> reference_normals);

}  // namespace primseg
