#pragma once
// Helpers of the denoising tests: noise along vertex normals and orientation checks.

#include <cstdint>

#include "primseg/mesh.hpp"

namespace primseg::testing {

/// Adds Gaussian noise of standard deviation `sigma` (input units) to every vertex along its
/// area-weighted unit normal. Deterministic for a seed on every platform.
Mesh with_normal_noise(const Mesh& mesh, double sigma, std::uint64_t seed);

/// Triangles whose normal in `after` points against their normal in `reference` (same
/// connectivity): dot < 0. A triangle of zero area in either is not counted.
std::uint32_t inverted_triangles(const Mesh& reference, const Mesh& after);

}  // namespace primseg::testing
