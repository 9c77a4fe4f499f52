// Directions: planes' normals and cylinders' axes with their uncertainty, grouped where they
// agree, and groups at right angles made exactly orthogonal.
#include "regularity/stages.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <queue>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include "eigen_conversions.hpp"
#include "orthonormal_pair.hpp"
#include "rotation_between.hpp"
#include "symmetric_eigen2.hpp"

namespace primseg::detail {

namespace {

// Two directions the right angles made one, to round-off (radians).
constexpr double kSameDirection = 1e-12;

// An item's information about its group's direction: Fᵢ Cᵢ⁻¹ Fᵢᵀ.
Eigen::Matrix3d direction_information(const Oriented& item) {
  return item.frame * item.covariance.inverse() * item.frame.transpose();
}

// The covariance of a direction's tilt from the eigen-decomposition of its information: the
// inverse across it, over the two largest eigenvalues (the direction is the smallest's).
Eigen::Matrix3d tilt_covariance(const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>& eigen) {
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (int k = 1; k < 3; ++k)
    covariance += eigen.eigenvectors().col(k) * eigen.eigenvectors().col(k).transpose() /
                  eigen.eigenvalues()(k);
  return covariance;
}

}  // namespace

void form_direction(DirectionGroup& group) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(group.information);
  group.direction = eigen.eigenvectors().col(0);
  group.covariance = tilt_covariance(eigen);
}

double angle_between_lines(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

std::optional<Oriented> oriented_plane(std::size_t cluster, std::span<const Vec3> points) {
  const std::size_t n = points.size();
  if (n < 6) return std::nullopt;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Vec3& p : points) centroid += to_eigen(p);
  centroid /= static_cast<double>(n);
  Oriented item;
  item.cluster = cluster;
  // The unweighted least-squares plane's: its tilt has variance σ̂²/λ along each in-plane
  // eigenvector of the scatter S (eigenvalue λ), and Σ Fᵢ Cᵢ⁻¹ Fᵢᵀ over a group of planes is their
  // summed scatter (less the residual terms), whose smallest eigenvector is their joint normal.
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Vec3& p : points) {
    const Eigen::Vector3d e = to_eigen(p) - centroid;
    scatter += e * e.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  item.direction = eigen.eigenvectors().col(0);
  const double extent2 = std::max(eigen.eigenvalues()(2), 0.0) / double(n);
  const double residual_variance = std::max(std::max(eigen.eigenvalues()(0), 0.0) / double(n - 3),
                                            kResolution * kResolution * extent2);
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
  const auto [u, v] = orthonormal_pair(a);
  item.direction = a;
  item.frame.col(0) = u;
  item.frame.col(1) = v;
  // Information of the parameters (tilt along u and v times the radius, so that every column is
  // in the same units and the result does not depend on them; shift of the axis along u and v;
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
      information.inverse() *
      std::max(residuals / double(n - 5), kResolution * kResolution * radius * radius);
  if (!covariance.allFinite()) return std::nullopt;
  item.covariance = covariance.topLeftCorner<2, 2>() / (radius * radius);
  item.variance = larger_eigenvalue(item.covariance);
  return item;
}

std::vector<DirectionGroup> group_directions(const std::vector<Oriented>& items,
                                             const RegularityOptions& options) {
  std::vector<std::size_t> order(items.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return items[a].variance < items[b].variance;
  });
  const double max_angle = options.max_angle_degrees * std::numbers::pi / 180;
  std::vector<DirectionGroup> groups;
  const double bound = chi_square_bound(options.significance, 2);  // a tilt's 2 coordinates
  for (const std::size_t i : order) {
    const Oriented& item = items[i];
    std::size_t best = groups.size();
    double best_score = bound;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const double angle = angle_between_lines(item.direction, groups[g].direction);
      if (angle > max_angle) continue;
      Eigen::Vector3d direction = groups[g].direction;
      if (direction.dot(item.direction) < 0) direction = -direction;
      const Eigen::Vector2d delta = item.frame.transpose() * direction;
      const Eigen::Matrix2d combined =
          item.covariance + item.frame.transpose() * groups[g].covariance * item.frame;
      const double score =
          tolerated(delta.dot(combined.ldlt().solve(delta)), bound, angle, options.angle_tolerance);
      if (score <= best_score) {
        best_score = score;
        best = g;
      }
    }
    if (best == groups.size()) groups.emplace_back().direction = item.direction;
    DirectionGroup& group = groups[best];
    group.members.push_back(i);
    group.information += direction_information(item);
    form_direction(group);
  }
  return groups;
}

void count_as_one(DirectionGroup& group, const std::vector<Oriented>& items,
                  std::span<const std::size_t> set, const Oriented& joined) {
  for (const std::size_t i : group.members)
    if (std::binary_search(set.begin(), set.end(), items[i].cluster))
      group.information -= direction_information(items[i]);
  group.information += direction_information(joined);
}

namespace {

// Moves directions a and b (unit) to be orthogonal, each along its own covariance: the
// least-squares correction, repeated until the cosine is below 1e-15. False when it does not get
// there.
bool make_orthogonal(Eigen::Vector3d& a, const Eigen::Matrix3d& covariance_a, Eigen::Vector3d& b,
                     const Eigen::Matrix3d& covariance_b) {
  for (int step = 0; step < 100; ++step) {
    const double cosine = a.dot(b);
    if (std::abs(cosine) <= 1e-15) return true;
    const Eigen::Vector3d move_a = covariance_a * b, move_b = covariance_b * a;
    const double scale = cosine / (b.dot(move_a) + a.dot(move_b));
    if (!std::isfinite(scale)) return false;
    a = (a - scale * move_a).normalized();
    b = (b - scale * move_b).normalized();
  }
  return false;
}

// The most groups a frame (a component closing a triangle of right angles) is solved over.
constexpr std::size_t kLargestFrame = 16;

using GroupPair = std::pair<std::size_t, std::size_t>;

// The directions of a frame's groups `component` (their order) with the right angle (i, j) added
// to its kept ones (`adjacent`): least squares from their measurements, by sweeps of
// make_orthogonal over every right angle; nothing when the sweeps do not converge.
std::optional<std::vector<Eigen::Vector3d>> solve_frame(
    std::size_t i, std::size_t j, const std::vector<std::size_t>& component,
    const std::vector<std::vector<std::size_t>>& adjacent,
    const std::vector<Eigen::Vector3d>& measured, const std::vector<Eigen::Vector3d>& solved,
    const std::vector<DirectionGroup>& groups) {
  std::vector<GroupPair> constraints{{i, j}};
  for (const std::size_t g : component)
    for (const std::size_t h : adjacent[g])
      if (g < h) constraints.emplace_back(g, h);
  std::vector<Eigen::Vector3d> d = solved;
  for (const std::size_t g : component) d[g] = measured[g];
  bool converged = false;
  for (int sweep = 0; sweep < 200 && !converged; ++sweep) {
    converged = true;
    for (const auto& [a, b] : constraints)
      if (std::abs(d[a].dot(d[b])) > 1e-15) {
        converged = false;
        make_orthogonal(d[a], groups[a].covariance, d[b], groups[b].covariance);
      }
  }
  if (!converged) return std::nullopt;
  std::vector<Eigen::Vector3d> moved;
  moved.reserve(component.size());
  for (const std::size_t g : component) moved.push_back(d[g]);
  return moved;
}

// The directions of a large component's groups `component` (their order), a tree joined by the
// right angle (i, j) between the trees of i (`first_tree`) and j: the pair's two directions meet,
// and each side turns rigidly with its own; nothing when they cannot meet.
std::optional<std::vector<Eigen::Vector3d>> turn_trees(std::size_t i, std::size_t j,
                                                       const std::vector<std::size_t>& component,
                                                       const std::vector<std::size_t>& component_of,
                                                       std::size_t first_tree,
                                                       const std::vector<Eigen::Vector3d>& solved,
                                                       const std::vector<DirectionGroup>& groups) {
  Eigen::Vector3d a = solved[i], b = solved[j];
  if (!make_orthogonal(a, groups[i].covariance, b, groups[j].covariance)) return std::nullopt;
  const Eigen::Quaterniond turn_i = rotation_between(solved[i], a);
  const Eigen::Quaterniond turn_j = rotation_between(solved[j], b);
  std::vector<Eigen::Vector3d> moved;
  moved.reserve(component.size());
  for (const std::size_t g : component)
    moved.push_back(
        g == i   ? a
        : g == j ? b
                 : ((component_of[g] == first_tree ? turn_i : turn_j) * solved[g]).normalized());
  return moved;
}

// Whether every direction of `component` ends, `moved`, within the significance of its
// measurement (or within the angle tolerance of it).
bool moves_within(const std::vector<std::size_t>& component,
                  const std::vector<Eigen::Vector3d>& moved,
                  const std::vector<Eigen::Vector3d>& measured,
                  const std::vector<DirectionGroup>& groups, const RegularityOptions& options) {
  const double bound = chi_square_bound(options.significance, 2);  // a tilt's
  for (std::size_t k = 0; k < component.size(); ++k) {
    const Eigen::Vector3d tilt = moved[k] - measured[component[k]];
    if (!(tilt.dot(groups[component[k]].information * tilt) <= bound ||
          within_tolerance(angle_between_lines(moved[k], measured[component[k]]),
                           options.angle_tolerance)))
      return false;
  }
  return true;
}

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> orthogonalize(std::vector<DirectionGroup>& groups,
                                                               const RegularityOptions& options) {
  const std::size_t count = groups.size();
  const double max_tilt = options.max_angle_degrees * std::numbers::pi / 180;
  const double significance2 = options.significance * options.significance;
  std::vector<Eigen::Vector3d> measured;
  measured.reserve(count);
  for (const DirectionGroup& group : groups) measured.push_back(group.direction);
  std::vector<Eigen::Vector3d> solved = measured;
  auto score = [&](std::size_t i, std::size_t j) {
    const Eigen::Vector3d &a = solved[i], &b = solved[j];
    const double cosine = a.dot(b);
    const double from_right_angle = std::abs(std::asin(std::clamp(cosine, -1.0, 1.0)));
    if (from_right_angle > max_tilt) return std::numeric_limits<double>::infinity();
    return tolerated(
        cosine * cosine / (b.dot(groups[i].covariance * b) + a.dot(groups[j].covariance * a)),
        significance2, from_right_angle, options.angle_tolerance);
  };
  // Min-queue of (score, i, j); a score is that of the directions when it was computed.
  using Entry = std::tuple<double, std::size_t, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (std::size_t i = 0; i < count; ++i)
    for (std::size_t j = i + 1; j < count; ++j)
      if (const double value = score(i, j); value <= 4 * significance2) queue.emplace(value, i, j);

  std::vector<std::vector<std::size_t>> adjacent(count);  // kept pairs, by group
  std::vector<std::size_t> component_of(count);
  std::vector<std::vector<std::size_t>> members(count);
  for (std::size_t g = 0; g < count; ++g) {
    component_of[g] = g;
    members[g] = {g};
  }
  std::vector<GroupPair> kept;
  while (!queue.empty()) {
    // Not a structured binding: clang 14 cannot capture one in the lambdas below.
    const double stale = std::get<0>(queue.top());
    const std::size_t i = std::get<1>(queue.top()), j = std::get<2>(queue.top());
    queue.pop();
    const double value = score(i, j);
    if (!(value <= 4 * significance2)) continue;
    // Scored again: wait for the pairs that now come first, or for good when it has not moved.
    if (value > stale || (!queue.empty() && value > std::get<0>(queue.top()))) {
      if (value > stale) queue.emplace(value, i, j);
      continue;
    }
    if (value > significance2) continue;
    const std::size_t ci = component_of[i], cj = component_of[j];
    std::vector<std::size_t> component = members[ci];
    if (ci != cj) component.insert(component.end(), members[cj].begin(), members[cj].end());
    std::optional<std::vector<Eigen::Vector3d>> moved;
    if (component.size() <= kLargestFrame) {
      // Within a component, only a pair that closes a triangle of right angles.
      if (ci == cj && std::none_of(adjacent[i].begin(), adjacent[i].end(), [&](std::size_t k) {
            return std::find(adjacent[j].begin(), adjacent[j].end(), k) != adjacent[j].end();
          }))
        continue;
      moved = solve_frame(i, j, component, adjacent, measured, solved, groups);
    } else if (ci != cj) {  // a large component is a tree: no triangle is closed in one
      moved = turn_trees(i, j, component, component_of, ci, solved, groups);
    }
    if (!moved || !moves_within(component, *moved, measured, groups, options)) continue;
    for (std::size_t k = 0; k < component.size(); ++k) solved[component[k]] = (*moved)[k];
    kept.emplace_back(i, j);
    adjacent[i].push_back(j);
    adjacent[j].push_back(i);
    if (ci != cj) {
      for (const std::size_t g : members[cj]) component_of[g] = ci;
      members[ci] = std::move(component);
      members[cj].clear();
    }
  }
  for (std::size_t g = 0; g < count; ++g) groups[g].direction = solved[g];
  std::sort(kept.begin(), kept.end());
  return kept;
}

void merge_parallel_groups(std::vector<DirectionGroup>& groups,
                           std::vector<std::pair<std::size_t, std::size_t>>& orthogonal,
                           std::vector<std::vector<std::vector<std::size_t>>>& coplanar) {
  std::vector<std::size_t> merged_into(groups.size());
  std::iota(merged_into.begin(), merged_into.end(), std::size_t{0});
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (merged_into[g] != g) continue;
    DirectionGroup& kept = groups[g];
    bool merged = false;
    for (std::size_t h = g + 1; h < groups.size(); ++h) {
      if (merged_into[h] != h ||
          !(kept.direction.cross(groups[h].direction).norm() <= kSameDirection))
        continue;
      merged_into[h] = g;
      merged = true;
      kept.members.insert(kept.members.end(), groups[h].members.begin(), groups[h].members.end());
      groups[h].members.clear();
      kept.information += groups[h].information;
      coplanar[g].insert(coplanar[g].end(), coplanar[h].begin(), coplanar[h].end());
      coplanar[h].clear();
    }
    if (!merged) continue;
    std::sort(kept.members.begin(), kept.members.end());
    // The tilt's covariance from the joint information across the kept direction.
    const Eigen::Matrix3d across =
        Eigen::Matrix3d::Identity() - kept.direction * kept.direction.transpose();
    kept.covariance = tilt_covariance(
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(across * kept.information * across));
  }
  for (auto& [i, j] : orthogonal) {
    i = merged_into[i];
    j = merged_into[j];
    if (i > j) std::swap(i, j);
  }
  std::sort(orthogonal.begin(), orthogonal.end());
  orthogonal.erase(std::unique(orthogonal.begin(), orthogonal.end()), orthogonal.end());
}

}  // namespace primseg::detail
