#pragma once
// Helpers of the denoising tests: noise along vertex normals and orientation checks.

#include <cstdint>

#include "primseg/cut.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh.hpp"

namespace primseg::testing {

/// Adds Gaussian noise of standard deviation `sigma` (input units) to every vertex along its
/// area-weighted unit normal. Deterministic for a seed on every platform.
Mesh with_normal_noise(const Mesh& mesh, double sigma, std::uint64_t seed);

/// Triangles whose normal in `after` points against their normal in `reference` (same
/// connectivity): dot < 0. A triangle of zero area in either is not counted.
std::uint32_t inverted_triangles(const Mesh& reference, const Mesh& after);

/// RMS over `mesh`'s vertices of their distance to `surface`'s triangles (input units).
double vertex_rms_to_surface(const Mesh& mesh, const Mesh& surface);

/// What is left of noise of deviation `sigma` along the normals after each cluster's primitive
/// is fitted to its noisy vertices by least squares and the vertices are moved onto it, when the
/// clusters are the true surfaces (input units): sigma · sqrt(P / V), P the degrees of freedom
/// of the level's primitives (plane 3, sphere 4, cylinder 5, cone 6, torus 7) and V the
/// vertices. The fitted values of P parameters from V measurements have a total variance of
/// P sigma² (the trace of the projection); no unbiased estimate does better (Cramér–Rao).
double least_squares_floor(const Hierarchy& hierarchy, const Segmentation& level, double sigma);

}  // namespace primseg::testing
