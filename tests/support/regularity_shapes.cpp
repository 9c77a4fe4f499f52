#include "regularity_shapes.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "eigen_conversions.hpp"
#include "primseg/geometric_fit.hpp"

namespace primseg::testing {

using detail::to_eigen;
using detail::to_vec3;

Cluster noisy_plane(const Eigen::Vector3d& normal, const Eigen::Vector3d& centre, double size,
                    double sigma, std::mt19937_64& rng, int n) {
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  Noise noise{sigma};
  Cluster cluster;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double s = size * (i / (n - 1.0) - 0.5), t = size * (j / (n - 1.0) - 0.5);
      cluster.points.push_back(to_vec3(centre + s * u + t * v + noise(rng) * normal));
      cluster.weights.push_back(1);
    }
  return cluster;
}

Cluster noisy_cylinder(const Eigen::Vector3d& axis, const Eigen::Vector3d& centre, double radius,
                       double length, double sigma, std::mt19937_64& rng, int rings) {
  const Eigen::Vector3d u = axis.unitOrthogonal(), v = axis.cross(u);
  Noise noise{sigma};
  Cluster cluster;
  for (int i = 0; i < rings; ++i)
    for (int k = 0; k < 24; ++k) {
      const double angle = 2 * std::numbers::pi * k / 24;
      const Eigen::Vector3d radial = std::cos(angle) * u + std::sin(angle) * v;
      const double t = length * (i / (rings - 1.0) - 0.5);
      cluster.points.push_back(to_vec3(centre + t * axis + (radius + noise(rng)) * radial));
      cluster.weights.push_back(1);
    }
  return cluster;
}

Cluster noisy_sphere_cap(const Eigen::Vector3d& centre, double radius, const Eigen::Vector3d& pole,
                         double polar_angle, double sigma, std::mt19937_64& rng) {
  const Eigen::Vector3d u = pole.unitOrthogonal(), v = pole.cross(u);
  Noise noise{sigma};
  Cluster cluster;
  for (int i = 1; i <= 10; ++i)
    for (int k = 0; k < 24; ++k) {
      const double polar = polar_angle * i / 10, azimuth = 2 * std::numbers::pi * k / 24;
      const Eigen::Vector3d radial =
          std::cos(polar) * pole +
          std::sin(polar) * (std::cos(azimuth) * u + std::sin(azimuth) * v);
      cluster.points.push_back(to_vec3(centre + (radius + noise(rng)) * radial));
      cluster.weights.push_back(1);
    }
  return cluster;
}

Mesh spherical_bowl(double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Noise noise{sigma};
  std::vector<Vec3> positions;
  std::vector<Triangle> triangles;
  // One side: its pole, then ring i (1..kBowlRings) at polar angle (π/2) i / kBowlRings from the
  // bottom.
  const auto side = [&](double radius) {
    const auto at = [&](double polar, double azimuth, double r) {
      return Vec3{kBowlCentre[0] + r * std::sin(polar) * std::cos(azimuth),
                  kBowlCentre[1] + r * std::sin(polar) * std::sin(azimuth),
                  kBowlCentre[2] - r * std::cos(polar)};
    };
    const auto pole = static_cast<std::uint32_t>(positions.size());
    positions.push_back(at(0, 0, radius + noise(rng)));
    for (int i = 1; i <= kBowlRings; ++i)
      for (int j = 0; j < kBowlAround; ++j)
        positions.push_back(at(std::numbers::pi / 2 * i / kBowlRings,
                               2 * std::numbers::pi * j / kBowlAround,
                               radius + (i < kBowlRings ? noise(rng) : 0.0)));
    const auto vertex = [pole](int i, int j) {
      return pole + 1 + static_cast<std::uint32_t>((i - 1) * kBowlAround + (j % kBowlAround));
    };
    for (int j = 0; j < kBowlAround; ++j)
      triangles.push_back({pole, vertex(1, j + 1), vertex(1, j)});
    for (int i = 1; i < kBowlRings; ++i)
      for (int j = 0; j < kBowlAround; ++j) {
        triangles.push_back({vertex(i, j), vertex(i, j + 1), vertex(i + 1, j + 1)});
        triangles.push_back({vertex(i, j), vertex(i + 1, j + 1), vertex(i + 1, j)});
      }
    return vertex;
  };
  const auto outer = side(1.0);
  const auto inner = side(0.8);
  for (int j = 0; j < kBowlAround; ++j) {
    triangles.push_back({outer(kBowlRings, j), inner(kBowlRings, j), inner(kBowlRings, j + 1)});
    triangles.push_back({outer(kBowlRings, j), inner(kBowlRings, j + 1), outer(kBowlRings, j + 1)});
  }
  return Mesh::from_triangles(std::move(positions), std::move(triangles));
}

Primitive fitted_plane(const Cluster& cluster) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Vec3& p : cluster.points) centroid += to_eigen(p);
  centroid /= static_cast<double>(cluster.points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Vec3& p : cluster.points)
    scatter += (to_eigen(p) - centroid) * (to_eigen(p) - centroid).transpose();
  Primitive plane;
  plane.type = PrimitiveType::Plane;
  plane.point = to_vec3(centroid);
  plane.axis =
      to_vec3(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0));
  return plane;
}

double angle_between_lines(const Vec3& a, const Vec3& b) {
  return std::atan2(to_eigen(a).cross(to_eigen(b)).norm(), std::abs(to_eigen(a).dot(to_eigen(b))));
}

Relations regularize(std::vector<Primitive>& primitives, const std::vector<Cluster>& clusters,
                     const detail::RegularityOptions& options) {
  std::vector<std::vector<Vec3>> points;
  std::vector<std::vector<double>> weights;
  for (const Cluster& c : clusters) {
    points.push_back(c.points);
    weights.push_back(c.weights);
  }
  Relations relations;
  for (const detail::Relation& relation : detail::regularize(primitives, points, weights, options))
    relations.emplace_back(relation.kind, relation.members);
  return relations;
}

Primitive fitted_cylinder(const Cluster& cluster, const Eigen::Vector3d& axis,
                          const Eigen::Vector3d& point, double radius) {
  Primitive start;
  start.type = PrimitiveType::Cylinder;
  start.point = to_vec3(point);
  start.axis = to_vec3(axis);
  start.radius = radius;
  return fit_geometric(start, cluster.points, cluster.weights).primitive;
}

double axis_offset(const Primitive& a, const Primitive& b) {
  const Eigen::Vector3d axis = to_eigen(a.axis).normalized();
  const Eigen::Vector3d d = to_eigen(b.point) - to_eigen(a.point);
  return (d - d.dot(axis) * axis).norm();
}

Primitive fitted_sphere(const Cluster& cluster, const Eigen::Vector3d& centre, double radius) {
  Primitive start;
  start.type = PrimitiveType::Sphere;
  start.point = to_vec3(centre);
  start.radius = radius;
  return fit_geometric(start, cluster.points, cluster.weights).primitive;
}

ProfileSegment profile_line(const Eigen::Vector2d& from, const Eigen::Vector2d& to,
                            const Eigen::Vector2d& normal, int intervals) {
  ProfileSegment segment;
  for (int i = 0; i <= intervals; ++i)
    segment.push_back({from + (to - from) * (i / double(intervals)), normal});
  return segment;
}

ProfileSegment profile_arc(const Eigen::Vector2d& centre, double radius, double from_degrees,
                           double to_degrees, int intervals) {
  ProfileSegment segment;
  for (int i = 0; i <= intervals; ++i) {
    const double angle =
        (from_degrees + (to_degrees - from_degrees) * i / intervals) * std::numbers::pi / 180;
    const Eigen::Vector2d radial(std::cos(angle), std::sin(angle));
    segment.push_back({centre + radius * radial, radial});
  }
  return segment;
}

std::vector<Cluster> swept_profile(const std::vector<ProfileSegment>& segments, double sigma,
                                   std::mt19937_64& rng) {
  Noise noise{sigma};
  std::vector<Cluster> clusters(segments.size());
  for (int row = 0; row <= 20; ++row) {
    const double y = row / 20.0 - 0.5;
    for (std::size_t s = 0; s < segments.size(); ++s)
      for (std::size_t i = 0; i < segments[s].size(); ++i) {
        Vec3 point;
        if (s > 0 && i == 0) {
          point = clusters[s - 1].points.back();
        } else {
          const ProfilePoint& p = segments[s][i];
          const Eigen::Vector2d moved = p.position + noise(rng) * p.normal;
          point = {moved.x(), y, moved.y()};
        }
        clusters[s].points.push_back(point);
        clusters[s].weights.push_back(1);
      }
  }
  return clusters;
}

bool has_relation(const Relations& relations, Kind kind, const std::vector<std::size_t>& members) {
  return std::count(relations.begin(), relations.end(), std::pair{kind, members}) == 1;
}

detail::RegularityOptions with_tolerances(double angle, double length) {
  detail::RegularityOptions options;
  options.angle_tolerance = angle;
  options.length_tolerance = length;
  return options;
}

}  // namespace primseg::testing
