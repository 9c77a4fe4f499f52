#pragma once
// Putting back vertices whose new positions invert triangles (denoising's ensemble mean).

#include <cstdint>
#include <span>
#include <vector>

#include "primseg/mesh.hpp"

namespace primseg {

/// Gives every vertex of a triangle that `positions` inverts (its normal against
/// `reference_normals[t]`, shape (T), any length) its position in `safe`, pass after pass, until no
/// triangle is inverted; a triangle of zero area is not. `safe` must invert none: then each pass
/// puts back at least one vertex, and at worst all end at `safe`. `positions` and `safe` have one
/// entry per vertex. Returns how many vertices were put back.
std::uint32_t revert_inverted_triangles(std::span<Vec3> positions, std::span<const Vec3> safe,
                                        const std::vector<Triangle>& triangles,
                                        std::span<const Vec3> reference_normals);

}  // namespace primseg
