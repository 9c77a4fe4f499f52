// Planes: a direction group's planes refitted with its direction, those whose offsets agree as
// one plane.
#include "regularity/stages.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "eigen_conversions.hpp"

namespace primseg::detail {

namespace {

// Σ w and the weighted centroid of `points` (not finite when Σ w is 0).
struct WeightedCentroid {
  Eigen::Vector3d centroid;
  double weight = 0;
};

WeightedCentroid weighted_centroid(std::span<const Vec3> points, std::span<const double> weights) {
  WeightedCentroid middle{Eigen::Vector3d::Zero()};
  for (std::size_t k = 0; k < points.size(); ++k) {
    middle.weight += weights[k];
    middle.centroid += weights[k] * to_eigen(points[k]);
  }
  middle.centroid /= middle.weight;
  return middle;
}

}  // namespace

bool align_plane(Primitive& plane, const Eigen::Vector3d& direction, std::span<const Vec3> points,
                 std::span<const double> weights) {
  const WeightedCentroid middle = weighted_centroid(points, weights);
  if (!(middle.weight > 0)) return false;
  plane.axis = to_vec3(direction.dot(to_eigen(plane.axis)) < 0 ? -direction : direction);
  plane.point = to_vec3(middle.centroid);
  return true;
}

std::optional<AlignedPlane> aligned_plane(std::size_t cluster, const Eigen::Vector3d& direction,
                                          std::span<const Vec3> points,
                                          std::span<const double> weights) {
  const std::size_t n = points.size();
  if (n < 6) return std::nullopt;
  const WeightedCentroid middle = weighted_centroid(points, weights);
  if (!(middle.weight > 0)) return std::nullopt;
  AlignedPlane plane{cluster, middle.centroid};
  plane.weight = middle.weight;
  plane.offset = direction.dot(plane.centroid);
  double weight2 = 0, squares = 0, extent2 = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d e = to_eigen(points[k]) - plane.centroid;
    const double r = direction.dot(e);
    weight2 += weights[k] * weights[k];
    squares += weights[k] * r * r;
    extent2 += weights[k] * (e.squaredNorm() - r * r);
  }
  const double residual_variance = std::max(squares / plane.weight * double(n) / double(n - 3),
                                            kResolution * kResolution * extent2 / plane.weight);
  plane.variance = residual_variance * weight2 / (plane.weight * plane.weight);
  return plane;
}

void share_one_plane(const Eigen::Vector3d& direction, const std::vector<std::size_t>& set,
                     std::vector<Primitive>& primitives,
                     const std::vector<std::vector<double>>& weights,
                     std::vector<Relation>& relations) {
  double weight = 0, weighted = 0;
  for (const std::size_t c : set) {
    double own = 0;
    for (const double w : weights[c]) own += w;
    weight += own;
    weighted += own * direction.dot(to_eigen(primitives[c].point));
  }
  const double shared = weighted / weight;
  for (const std::size_t c : set) {
    const Eigen::Vector3d point = to_eigen(primitives[c].point);
    primitives[c].point = to_vec3(point - (direction.dot(point) - shared) * direction);
  }
  relations.push_back({Relation::Kind::Coplanar, set, {}});
}

std::vector<std::vector<std::size_t>> coplanar_sets(const Eigen::Matrix3d& direction_covariance,
                                                    std::vector<AlignedPlane> planes,
                                                    const RegularityOptions& options) {
  const double significance = options.significance;
  std::stable_sort(planes.begin(), planes.end(), [](const AlignedPlane& a, const AlignedPlane& b) {
    return a.variance < b.variance;
  });
  struct Set {
    std::vector<std::size_t> planes;       // indices into `planes`
    double information = 0, weighted = 0;  // Σ 1/variance, Σ offset/variance
  };
  const double bound = chi_square_bound(significance, 1);
  std::vector<Set> sets;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    std::size_t joined = sets.size();
    for (std::size_t s = 0; s < sets.size() && joined == sets.size(); ++s) {
      const double offset = planes[i].offset - sets[s].weighted / sets[s].information;
      const Eigen::Vector3d apart = planes[i].centroid - planes[sets[s].planes[0]].centroid;
      const double variance =
          planes[i].variance + 1 / sets[s].information + apart.dot(direction_covariance * apart);
      if (offset * offset <= bound * variance ||
          within_tolerance(std::abs(offset), options.length_tolerance))
        joined = s;
    }
    if (joined == sets.size()) sets.emplace_back();
    sets[joined].planes.push_back(i);
    sets[joined].information += 1 / planes[i].variance;
    sets[joined].weighted += planes[i].offset / planes[i].variance;
  }
  // One plane through a set's members' inliers (the weighted mean of their offsets), and how it
  // moves them.
  struct Assessed {
    double shared = 0;
    GuardExcess excess;
  };
  const auto assess = [&](const std::vector<std::size_t>& set) {
    double weight = 0, weighted = 0;
    Eigen::Vector3d middle = Eigen::Vector3d::Zero();  // where the shared plane pivots
    for (const std::size_t i : set) {
      weight += planes[i].weight;
      weighted += planes[i].weight * planes[i].offset;
      middle += planes[i].weight * planes[i].centroid;
    }
    Assessed result;
    result.shared = weighted / weight;
    middle /= weight;
    const double member_bound = family_significance(significance, set.size());
    for (std::size_t j = 0; j < set.size(); ++j) {
      // The member's residual sum rises by its weight times the move², against the bound times
      // its residual variance: the move against its offset's standard deviation, with the
      // direction's tilt over its distance from where the shared plane pivots.
      const AlignedPlane& plane = planes[set[j]];
      const double moved = plane.offset - result.shared;
      const Eigen::Vector3d apart = plane.centroid - middle;
      const double excess =
          tolerated(moved * moved /
                        (member_bound * member_bound *
                         (plane.variance + apart.dot(direction_covariance * apart))),
                    1, std::abs(moved), options.length_tolerance);
      result.excess.add(excess, j);
    }
    return result;
  };
  std::vector<std::vector<std::size_t>> coplanar;
  for (std::size_t s = 0; s < sets.size(); ++s) {
    // Moved out: the members that leave are a set of their own, which may reallocate `sets`.
    std::vector<std::size_t> set = std::move(sets[s].planes);
    // The plane of the members left: after a member leaves, the one found while choosing it.
    std::optional<Assessed> all;
    std::vector<std::size_t> left;  // the members that leave: a set of their own, tested in turn
    while (set.size() > 1) {
      if (!all) all = assess(set);
      if (!(all->excess.largest > 1)) break;
      auto [leaving, without_leaving] = member_that_leaves(
          every_member(set.size()), all->excess.worst,
          [&](std::size_t j) {
            const double force = planes[set[j]].weight * (planes[set[j]].offset - all->shared);
            return force * force;
          },
          [&](std::size_t j) {
            std::vector<std::size_t> others = set;
            others.erase(others.begin() + static_cast<std::ptrdiff_t>(j));
            return assess(others);
          });
      left.push_back(set[leaving]);
      set.erase(set.begin() + static_cast<std::ptrdiff_t>(leaving));
      all = without_leaving;
    }
    if (!left.empty()) {
      std::sort(left.begin(), left.end());  // best located first
      sets.push_back({std::move(left)});
    }
    if (set.size() < 2) continue;
    std::vector<std::size_t>& clusters = coplanar.emplace_back();
    for (const std::size_t i : set) clusters.push_back(planes[i].cluster);
    std::sort(clusters.begin(), clusters.end());
  }
  return coplanar;
}

bool count_coplanar_as_one(DirectionGroup& group, const std::vector<Oriented>& items,
                           const std::vector<std::vector<std::size_t>>& sets,
                           const std::vector<std::vector<Vec3>>& points) {
  bool counted = false;
  for (const std::vector<std::size_t>& set : sets) {
    std::vector<Vec3> union_points;
    for (const std::size_t c : set)
      union_points.insert(union_points.end(), points[c].begin(), points[c].end());
    const std::optional<Oriented> joined = oriented_plane(set[0], union_points);
    if (!joined || !(joined->variance > 0)) continue;
    count_as_one(group, items, set, *joined);
    counted = true;
  }
  return counted;
}

}  // namespace primseg::detail
