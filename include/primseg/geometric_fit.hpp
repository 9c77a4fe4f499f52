#pragma once
/// @file geometric_fit.hpp
/// Geometric (true Euclidean distance) least-squares refinement of a fitted primitive.
///
/// The hierarchy fits primitives algebraically from additive statistics (fast, first-order
/// accurate). The parameters a user reads are refined here: Levenberg–Marquardt on
/// Σ w_i d(x_i)², d the Euclidean distance of point x_i to the surface, started from the
/// algebraic fit. Each type provides its distance and derivatives through a small model
/// (src/geometric_models.hpp); types without one are returned unchanged.

#include <span>

#include "primseg/primitive.hpp"

namespace primseg {

/// Options of fit_geometric().
struct GeometricFitOptions {
  /// Levenberg–Marquardt iterations at most (each one O(number of points)).
  int max_iterations = 100;
  /// Stops when a step lowers Σ w d² by less than this fraction of it.
  double relative_tolerance = 1e-15;
};

/// Result of fit_geometric().
struct GeometricFit {
  /// The refined primitive, same type as the initial one, in canonical form (primitive.hpp);
  /// the initial one if the type has no geometric model or nothing lowered the error.
  Primitive primitive;
  double rms = 0;      ///< sqrt(Σ w d² / Σ w) of the refined primitive, units of the points
  double max = 0;      ///< largest d of a point of positive weight
  int iterations = 0;  ///< accepted steps
};

/// Refines `initial` to the weighted points (shape (n, 3) and (n), weights >= 0, same units as
/// the primitive). A plane's normal keeps the side of the initial one; a cylinder's point is
/// the weighted centroid projected on the axis. Deterministic. Throws InvalidInputError for
/// sizes that differ or a negative or non-finite weight.
GeometricFit fit_geometric(const Primitive& initial, std::span<const Vec3> points,
                           std::span<const double> weights,
                           const GeometricFitOptions& options = {});

/// fit_geometric(), except for a torus whose ring the fit shrinks to (nearly) a point
/// (torus_ring_vanishes: major radius below kMinRelativeTorusMajorRadius × the minor one): its
/// surface is then the sphere of its tube, so that sphere is refitted and returned instead, with
/// four parameters for seven. `iterations` counts both fits' steps. What reports and the denoiser
/// use, so that neither lists a torus that is a sphere.
GeometricFit fit_geometric_or_sphere(const Primitive& initial, std::span<const Vec3> points,
                                     std::span<const double> weights,
                                     const GeometricFitOptions& options = {});

/// Whether a type has a geometric model (otherwise fit_geometric returns it unchanged).
bool has_geometric_model(PrimitiveType type);

}  // namespace primseg
