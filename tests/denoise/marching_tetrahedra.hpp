#pragma once
// Surfaces resampled from a signed distance field, the way a scanner's reconstruction or a voxel
// remesher resamples them: sharp edges and corners come out chamfered.

#include <array>
#include <functional>

#include "primseg/mesh.hpp"

namespace primseg::testing {

/// Zero level set of `signed_distance` (negative inside) by marching tetrahedra over a grid of
/// cubes of side `spacing` whose nodes are low + spacing·(i, j, k), i, j, k in 0..count[axis].
/// Each cube is cut into the 6 tetrahedra around its main diagonal (conforming between cubes),
/// vertices on grid edges are shared, and triangles face the positive side: a closed field
/// inside the grid gives a closed, manifold, outward-oriented mesh. No node may lie exactly on
/// the surface (offset the grid).
Mesh marching_tetrahedra(const std::function<double(const Vec3&)>& signed_distance, const Vec3& low,
                         double spacing, const std::array<int, 3>& count);

/// Exact signed distance to the box of the given half-extents centred at the origin.
double box_signed_distance(const Vec3& p, const Vec3& half_extents);

/// The box of the given half-extents centred at the origin as 12 outward triangles.
Mesh box_mesh(const Vec3& half_extents);

}  // namespace primseg::testing
