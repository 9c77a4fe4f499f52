#include "regularity.hpp"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>
#include <span>
#include <utility>

#include "eigen_conversions.hpp"

namespace primseg::detail {
namespace {

// A primitive with a direction (a plane's normal, a cylinder's axis) and how well its inliers
// determine it.
struct Oriented {
  std::size_t cluster = 0;
  Eigen::Vector3d direction;
  double variance = 0;  // of its tilt, radians², in the worst direction
  // Covariance of the tilt (radians²) along the tangent directions `frame` (columns).
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  Eigen::Matrix<double, 3, 2> frame;
};

// Directions tested parallel, and their common direction: the minimiser over unit d of
// Σ δᵢᵀ Cᵢ⁻¹ δᵢ, δᵢ the tilt of d from member i's direction in its frame, which is the smallest
// eigenvector of Σ Fᵢ Cᵢ⁻¹ Fᵢᵀ (for a plane, its scatter matrix over the residual variance).
struct DirectionGroup {
  Eigen::Vector3d direction;
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // of the direction's tilt
  std::vector<std::size_t> members;                      // indices into the Oriented items
};

// An orthonormal basis (u, v) of the plane orthogonal to the unit vector `axis`.
std::pair<Eigen::Vector3d, Eigen::Vector3d> plane_basis(const Eigen::Vector3d& axis) {
  Eigen::Index least_aligned;
  axis.cwiseAbs().minCoeff(&least_aligned);
  const Eigen::Vector3d u = axis.cross(Eigen::Vector3d::Unit(least_aligned)).normalized();
  return {u, axis.cross(u)};
}

double angle_between_lines(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

std::optional<Oriented> oriented_plane(std::size_t cluster, const Primitive& plane,
                                       std::span<const Vec3> points) {
  const std::size_t n = points.size();
  if (n < 6) return std::nullopt;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Vec3& p : points) centroid += to_eigen(p);
  centroid /= static_cast<double>(n);
  Oriented item;
  item.cluster = cluster;
  item.direction = to_eigen(plane.axis).normalized();
  Eigen::Matrix3d plain = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d e = to_eigen(points[i]) - centroid;
    plain += e * e.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(plain);
  const double residual_variance = std::max(eigen.eigenvalues()(0), 0.0) / double(n - 3);
  if (!(eigen.eigenvalues()(1) > 0)) return std::nullopt;
  item.frame.col(0) = eigen.eigenvectors().col(1);
  item.frame.col(1) = eigen.eigenvectors().col(2);
  item.covariance = Eigen::Vector2d(residual_variance / eigen.eigenvalues()(1),
                                    residual_variance / eigen.eigenvalues()(2))
                        .asDiagonal();
  item.variance = item.covariance(0, 0);
  return item;
}

std::optional<Oriented> oriented_cylinder(std::size_t cluster, const Primitive& cylinder,
                                          std::span<const Vec3> points) {
  const std::size_t n = points.size();
  if (n < 12) return std::nullopt;
  Oriented item;
  item.cluster = cluster;
  const Eigen::Vector3d a = to_eigen(cylinder.axis).normalized(), p = to_eigen(cylinder.point);
  const auto [u, v] = plane_basis(a);
  item.direction = a;
  item.frame.col(0) = u;
  item.frame.col(1) = v;
  // Information of the parameters (tilt along u and v times the radius, so that every column is
  // in the same units and the tree does not depend on them; shift of the axis along u and v;
  // radius) from the residuals' Jacobian: e = |Q(x − p)| − r, Q = I − a aᵀ.
  const double radius = cylinder.radius;
  if (!(radius > 0)) return std::nullopt;
  Eigen::Matrix<double, 5, 5> information = Eigen::Matrix<double, 5, 5>::Zero();
  double residuals = 0;
  for (const Vec3& point : points) {
    const Eigen::Vector3d d = to_eigen(point) - p;
    const double t = a.dot(d);
    const Eigen::Vector3d radial = d - t * a;
    const double length = radial.norm();
    if (!(length > 0)) continue;
    const Eigen::Vector3d normal = radial / length;
    const double e = length - radius;
    residuals += e * e;
    Eigen::Matrix<double, 5, 1> j;
    j << -t / radius * normal.dot(u), -t / radius * normal.dot(v), -normal.dot(u), -normal.dot(v),
        -1;
    information += j * j.transpose();
  }
  const Eigen::Matrix<double, 5, 5> covariance =
      information.inverse() * (residuals / double(n - 5));
  if (!covariance.allFinite()) return std::nullopt;
  item.covariance = covariance.topLeftCorner<2, 2>() / (radius * radius);
  item.variance = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(item.covariance).eigenvalues()(1);
  return item;
}

// The cylinder with axis direction `axis` nearest to the points (geometric least squares, from
// the projection of `start`): Gauss–Newton on the circle of the projected points.
Primitive cylinder_with_axis(const Primitive& start, const Eigen::Vector3d& axis,
                             std::span<const Vec3> points, std::span<const double> weights) {
  const auto [u, v] = plane_basis(axis);
  const Eigen::Vector3d origin = to_eigen(start.point);
  std::vector<Eigen::Vector2d> q(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d d = to_eigen(points[i]) - origin;
    q[i] = {u.dot(d), v.dot(d)};
  }
  Eigen::Vector3d x(0, 0, start.radius);  // centre (2D) and radius
  for (int step = 0; step < 30; ++step) {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < q.size(); ++i) {
      const Eigen::Vector2d d = q[i] - x.head<2>();
      const double length = d.norm();
      if (!(length > 0)) continue;
      const Eigen::Vector3d j(-d.x() / length, -d.y() / length, -1);
      const double e = length - x.z();
      normal += weights[i] * j * j.transpose();
      gradient += weights[i] * j * e;
    }
    const Eigen::Vector3d delta = normal.ldlt().solve(-gradient);
    if (!delta.allFinite()) break;
    x += delta;
    if (!(delta.norm() > 1e-14 * (std::abs(x.z()) + x.head<2>().norm()))) break;
  }
  if (!x.allFinite() || !(x.z() != 0)) return start;
  Primitive cylinder = start;
  cylinder.axis = to_vec3(axis.dot(to_eigen(start.axis)) < 0 ? -axis : axis);
  cylinder.point = to_vec3(origin + x.x() * u + x.y() * v);
  cylinder.radius = std::abs(x.z());
  return cylinder;
}

}  // namespace

void regularize(std::vector<Primitive>& primitives, const std::vector<std::vector<Vec3>>& points,
                const std::vector<std::vector<double>>& weights, const RegularityOptions& options) {
  std::vector<Oriented> items;
  for (std::size_t c = 0; c < primitives.size(); ++c) {
    std::optional<Oriented> item;
    if (primitives[c].type == PrimitiveType::Plane)
      item = oriented_plane(c, primitives[c], points[c]);
    else if (primitives[c].type == PrimitiveType::Cylinder)
      item = oriented_cylinder(c, primitives[c], points[c]);
    if (item && std::isfinite(item->variance) && item->variance > 0) items.push_back(*item);
  }
  // The best-determined directions first.
  std::vector<std::size_t> order(items.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return items[a].variance < items[b].variance;
  });
  const double max_angle = options.max_angle_degrees * std::numbers::pi / 180;
  const double significance2 = options.significance * options.significance;
  std::vector<DirectionGroup> groups;
  for (const std::size_t i : order) {
    const Oriented& item = items[i];
    std::size_t best = groups.size();
    double best_score = significance2;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const double angle = angle_between_lines(item.direction, groups[g].direction);
      if (angle > max_angle) continue;
      Eigen::Vector3d direction = groups[g].direction;
      if (direction.dot(item.direction) < 0) direction = -direction;
      const Eigen::Vector2d delta = item.frame.transpose() * direction;
      const Eigen::Matrix2d combined =
          item.covariance + item.frame.transpose() * groups[g].covariance * item.frame;
      const double score = delta.dot(combined.ldlt().solve(delta));
      if (score <= best_score) {
        best_score = score;
        best = g;
      }
    }
    if (best == groups.size()) groups.emplace_back().direction = item.direction;
    DirectionGroup& group = groups[best];
    group.members.push_back(i);
    group.information += item.frame * item.covariance.inverse() * item.frame.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(group.information);
    group.direction = eigen.eigenvectors().col(0);
    group.covariance.setZero();
    for (int k = 1; k < 3; ++k)
      group.covariance += eigen.eigenvectors().col(k) * eigen.eigenvectors().col(k).transpose() /
                          eigen.eigenvalues()(k);
  }
  for (const DirectionGroup& group : groups) {
    if (group.members.size() < 2) continue;
    for (const std::size_t i : group.members) {
      const std::size_t c = items[i].cluster;
      Primitive& primitive = primitives[c];
      if (primitive.type == PrimitiveType::Plane) {
        Eigen::Vector3d direction = group.direction;
        if (direction.dot(to_eigen(primitive.axis)) < 0) direction = -direction;
        double total = 0;
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (std::size_t k = 0; k < points[c].size(); ++k) {
          total += weights[c][k];
          centroid += weights[c][k] * to_eigen(points[c][k]);
        }
        if (!(total > 0)) continue;
        primitive.axis = to_vec3(direction);
        primitive.point = to_vec3(centroid / total);
      } else {
        primitive = cylinder_with_axis(primitive, group.direction, points[c], weights[c]);
      }
    }
  }
}

}  // namespace primseg::detail
