#pragma once
// Clusters sampled from planes, cylinders, spheres and swept profiles with known answers, their
// own fits, and detail::regularize() on them: the fixtures of tests/regularity/regularity_test.cpp
// and tests/regularity/tangency_test.cpp.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "primseg/mesh.hpp"
#include "primseg/primitive.hpp"
#include "regularity.hpp"

namespace primseg::testing {

/// A cluster's inlier points (the shape's units) and their weights (all 1 here).
struct Cluster {
  std::vector<Vec3> points;
  std::vector<double> weights;
};

/// Gaussian noise of deviation `sigma`; none at all for sigma 0 (an exact part).
struct Noise {
  double sigma;
  std::normal_distribution<double> standard{};
  double operator()(std::mt19937_64& rng) { return sigma * standard(rng); }
};

/// An n × n grid of side `size` on the plane through `centre` with normal `normal`, each point
/// moved along the normal by Gaussian noise of deviation `sigma`.
Cluster noisy_plane(const Eigen::Vector3d& normal, const Eigen::Vector3d& centre, double size,
                    double sigma, std::mt19937_64& rng, int n = 20);

/// A cylinder of radius `radius` around the axis through `centre`, `rings` rings of 24 points
/// over `length`, moved radially by Gaussian noise of deviation `sigma` (0: exact).
Cluster noisy_cylinder(const Eigen::Vector3d& axis, const Eigen::Vector3d& centre, double radius,
                       double length, double sigma, std::mt19937_64& rng, int rings = 20);

/// A spherical cap of radius `radius` about `centre`, facing `pole`: 10 rings of 24 points from
/// the pole down to `polar_angle` (radians), moved radially by Gaussian noise of deviation
/// `sigma` (0: exact).
Cluster noisy_sphere_cap(const Eigen::Vector3d& centre, double radius, const Eigen::Vector3d& pole,
                         double polar_angle, double sigma, std::mt19937_64& rng);

/// A hemispherical bowl: the outer side a hemisphere of radius 1 about kBowlCentre below its
/// equator, the inner side one of radius 0.8 about the same centre, joined by the flat rim between
/// them (kBowlRings rings of kBowlAround vertices on each side): a closed shell of three surfaces,
/// 2,304 triangles. Each sphere vertex is moved along its radius by Gaussian noise of deviation
/// `sigma` (0: exact); the rim's vertices stay on the rim.
inline constexpr std::array<double, 3> kBowlCentre{0.3, -0.2, 0.5};
inline constexpr int kBowlRings = 12, kBowlAround = 48;
Mesh spherical_bowl(double sigma, std::uint64_t seed);

/// A profile in the xz-plane, swept along y by swept_profile(): a point and its unit normal.
struct ProfilePoint {
  Eigen::Vector2d position, normal;  ///< (x, z)
};
using ProfileSegment = std::vector<ProfilePoint>;

/// `intervals` + 1 points from `from` to `to`, all of normal `normal`.
ProfileSegment profile_line(const Eigen::Vector2d& from, const Eigen::Vector2d& to,
                            const Eigen::Vector2d& normal, int intervals);

/// `intervals` + 1 points of the circle of radius `radius` about `centre`, from the angle
/// `from_degrees` to `to_degrees` (from the x axis towards z), with outward normals.
ProfileSegment profile_arc(const Eigen::Vector2d& centre, double radius, double from_degrees,
                           double to_degrees, int intervals);

/// `segments` swept along y over [-0.5, 0.5] (21 rows): segment s's points are cluster s, each
/// moved along its normal by Gaussian noise of deviation `sigma`; consecutive segments share
/// their junction, a border vertex of both (one noisy point).
std::vector<Cluster> swept_profile(const std::vector<ProfileSegment>& segments, double sigma,
                                   std::mt19937_64& rng);

/// Least-squares plane (PCA), as the denoiser's refit gives it.
Primitive fitted_plane(const Cluster& cluster);

/// The geometric least-squares cylinder of `cluster` from a start (fit_geometric()).
Primitive fitted_cylinder(const Cluster& cluster, const Eigen::Vector3d& axis,
                          const Eigen::Vector3d& point, double radius);

/// The geometric least-squares sphere of `cluster` from a start (fit_geometric()).
Primitive fitted_sphere(const Cluster& cluster, const Eigen::Vector3d& centre, double radius);

/// The angle between two lines' directions, in [0, π/2] (radians).
double angle_between_lines(const Vec3& a, const Vec3& b);

/// The distance between the axis lines of two cylinders with parallel axes.
double axis_offset(const Primitive& a, const Primitive& b);

using Kind = detail::Relation::Kind;

/// The relations regularize() made, as (kind, members) pairs in its order.
using Relations = std::vector<std::pair<Kind, std::vector<std::size_t>>>;

/// detail::regularize() on the clusters' points and weights; `primitives` are refitted in place.
Relations regularize(std::vector<Primitive>& primitives, const std::vector<Cluster>& clusters,
                     const detail::RegularityOptions& options = {});

/// Whether `relations` holds the relation (kind, members) once.
bool has_relation(const Relations& relations, Kind kind, const std::vector<std::size_t>& members);

/// Default options with an angle tolerance (radians) and a length tolerance.
detail::RegularityOptions with_tolerances(double angle, double length);

}  // namespace primseg::testing
