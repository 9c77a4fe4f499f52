#pragma once
// What the stages of regularize() share across their sources: the directions, axis lines,
// coplanar sets, spheres and radii in regularity.cpp, the tangencies in regularity_tangency.cpp.

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "primseg/primitive.hpp"
#include "regularity.hpp"

namespace primseg::detail {

/// A fit's residual deviation is never taken below this fraction of its size (a plane's extent,
/// a cylinder's radius). An exact input (a CAD tessellation) has residuals of rounding only, which
/// would make every direction and axis certain beyond its own rounding and no two of them equal;
/// any measured surface has residuals far above it.
inline constexpr double kResolution = 1e-9;

/// Not in a relation yet.
inline constexpr std::size_t kNoRelation = std::numeric_limits<std::size_t>::max();

/// Directions tested parallel, and their common direction: the minimiser over unit d of
/// Σ δᵢᵀ Cᵢ⁻¹ δᵢ, δᵢ the tilt of d from member i's direction in its frame, which is the smallest
/// eigenvector of Σ Fᵢ Cᵢ⁻¹ Fᵢᵀ (for a plane, its scatter matrix over the residual variance).
struct DirectionGroup {
  Eigen::Vector3d direction;
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< of the direction's tilt (radians²)
  std::vector<std::size_t> members;                      ///< indices into the oriented items
};

/// A cylinder of several on one axis line, each with its own radius: its inliers (input units),
/// their weights, and its radius (a fit's start).
struct CoaxialMember {
  std::span<const Vec3> points;
  std::span<const double> weights;
  double radius = 0;
};

/// Whether a difference of size `size` is within a tolerance (RegularityOptions::angle_tolerance,
/// length_tolerance), which then passes a test whatever its statistic; never for a tolerance of 0.
bool within_tolerance(double size, double tolerance);

/// A test's score with a tolerance, where candidates rank by their scores: passed at or below
/// `bound`, it also passes when within_tolerance(size, tolerance), and such a difference then
/// ranks by its size against the tolerance. A tolerance of 0 leaves the score as it is.
double tolerated(double score, double bound, double size, double tolerance);

/// The χ² value a sum of `freedom` squared standard normals exceeds as rarely as one normal
/// exceeds `significance` in magnitude: exact for one and two degrees of freedom,
/// Wilson–Hilferty's approximation beyond (within 2% from three on at a significance of 3).
double chi_square_bound(double significance, std::size_t freedom);

/// How far a joint fit explains a member worse than its own fit did: the rise of its residual sum
/// over significance² times its residual variance (estimated with the degrees of freedom of the
/// member's own fit, of `parameters` parameters), or, when lower, the rise of its mean square
/// against the square of the length tolerance. Above 1, it does not belong.
double residual_excess(double own_rms, double joint_rms, std::size_t count, double significance2,
                       int parameters, double length_tolerance);

/// `cylinder` on the line of `direction` through `centre` (orthonormal_pair(direction)
/// coordinates), its axis on its own side and its point the line's nearest to the old one, so
/// that it stays by the cluster.
void place_cylinder(Primitive& cylinder, const Eigen::Vector3d& direction,
                    const Eigen::Vector2d& centre, double radius);

/// How far apart the lines through two points along a unit `direction` are.
double distance_across(const Eigen::Vector3d& apart, const Eigen::Vector3d& direction);

/// Two circles (cylinders of one direction, seen along it) whose centres are `distance` apart
/// touch when it is the sum of their radii (each outside the other) or their difference (one
/// inside the other). The nearer condition for the circle of radius `radius` held tangent to the
/// one of radius `held`: |c − c'| = partner_sign · held + own_sign · radius, and the gap from it,
/// distance − (partner_sign · held + own_sign · radius).
struct CircleContact {
  double partner_sign = 1, own_sign = 1, gap = 0;
};
CircleContact nearest_circle_contact(double distance, double radius, double held);

/// The tangency stage of regularize() (RegularityOptions::tangency): cylinders held tangent to
/// the planes and the larger parallel cylinders they border, from the direction `groups`, the
/// pairs of them made `orthogonal`, the clusters each group `refitted`, and the `relations` made so
/// far. Writes the cylinders and planes it moves into `primitives`, and appends a Tangent relation
/// per pair to `tangents`. The rules are at its definition.
void make_tangent(const std::vector<DirectionGroup>& groups,
                  const std::vector<std::pair<std::size_t, std::size_t>>& orthogonal,
                  const std::vector<std::vector<std::size_t>>& refitted,
                  const RegularityOptions& options, std::vector<Primitive>& primitives,
                  const std::vector<std::vector<Vec3>>& points,
                  const std::vector<std::vector<double>>& weights,
                  const std::vector<Relation>& relations, std::vector<Relation>& tangents);

}  // namespace primseg::detail
