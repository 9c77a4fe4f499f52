// regularize() and its entry points: the stages in order (src/regularity/stages.hpp), then each
// relation's deviation.
#include "regularity.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include "eigen_conversions.hpp"
#include "regularity/stages.hpp"

namespace primseg::detail {
namespace {

// ClusterRelation::deviation of `related`: how far the clusters' own fits (`own`) were from it;
// `shared` holds the fits that make it exact. Degrees for directions, the points' units for
// lengths.
double deviation(const ClusterRelation& related, std::span<const Primitive> own,
                 std::span<const Primitive> shared) {
  using Kind = ClusterRelation::Kind;
  const std::vector<std::uint32_t>& members = related.clusters;
  const auto axis = [&](std::uint32_t c) { return to_eigen(own[c].axis); };
  const auto point = [&](std::uint32_t c) { return to_eigen(own[c].point); };
  constexpr double kDegrees = 180 / std::numbers::pi;
  double largest = 0;
  switch (related.kind) {
    case Kind::Parallel:
      for (const std::uint32_t c : members)
        largest = std::max(largest, angle_between_lines(axis(c), to_eigen(shared[c].axis)));
      return largest * kDegrees;
    case Kind::Orthogonal:
      for (const std::uint32_t a : members)
        for (const std::uint32_t b : related.orthogonal_to)
          largest = std::max(largest, std::numbers::pi / 2 - angle_between_lines(axis(a), axis(b)));
      return largest * kDegrees;
    case Kind::Coaxial: {
      // The shared line: a cylinder's, else (spheres alone) through the two centres farthest apart.
      Eigen::Vector3d on_line = Eigen::Vector3d::Zero(), along = Eigen::Vector3d::Zero();
      const auto cylinder = std::find_if(members.begin(), members.end(), [&](std::uint32_t c) {
        return shared[c].type == PrimitiveType::Cylinder;
      });
      if (cylinder != members.end()) {
        on_line = to_eigen(shared[*cylinder].point);
        along = to_eigen(shared[*cylinder].axis).normalized();
      } else {
        for (const std::uint32_t a : members)
          for (const std::uint32_t b : members) {
            const Eigen::Vector3d apart = to_eigen(shared[b].point) - to_eigen(shared[a].point);
            if (apart.norm() > along.norm()) {
              on_line = to_eigen(shared[a].point);
              along = apart;
            }
          }
        if (!(along.norm() > 0)) return 0;
        along.normalize();
      }
      for (const std::uint32_t c : members)
        largest = std::max(largest, (point(c) - on_line).cross(along).norm());
      return largest;
    }
    case Kind::EqualRadius: {
      const auto [smallest, biggest] = std::minmax_element(
          members.begin(), members.end(),
          [&](std::uint32_t a, std::uint32_t b) { return own[a].radius < own[b].radius; });
      return own[*biggest].radius - own[*smallest].radius;
    }
    case Kind::Coplanar: {
      const Eigen::Vector3d normal = to_eigen(shared[members[0]].axis);
      const Eigen::Vector3d on_plane = to_eigen(shared[members[0]].point);
      for (const std::uint32_t c : members)
        largest = std::max(largest, std::abs(normal.dot(point(c) - on_plane)));
      return largest;
    }
    case Kind::Tangent: {
      std::uint32_t c = members[0], p = members[1];
      if (own[c].type != PrimitiveType::Cylinder) std::swap(c, p);
      if (own[p].type == PrimitiveType::Plane)
        return std::abs(std::abs(axis(p).dot(point(c) - point(p))) - own[c].radius);
      // Two cylinders: the distance of the smaller one's axis, at its point, from the larger's
      // line, against the sum or the difference of their radii, whichever is nearer.
      if (own[c].radius > own[p].radius) std::swap(c, p);
      const double distance = distance_across(point(c) - point(p), axis(p).normalized());
      return std::abs(nearest_circle_contact(distance, own[c].radius, own[p].radius).gap);
    }
    case Kind::Concentric:
      for (const std::uint32_t c : members)
        largest = std::max(largest, (point(c) - to_eigen(shared[members[0]].point)).norm());
      return largest;
  }
  return 0;
}

// The planes and cylinders whose direction is known well enough to compare (a finite, positive
// variance), in cluster order.
std::vector<Oriented> oriented_items(const std::vector<Primitive>& primitives,
                                     const std::vector<std::vector<Vec3>>& points) {
  std::vector<Oriented> items;
  for (std::size_t c = 0; c < primitives.size(); ++c) {
    std::optional<Oriented> item;
    if (primitives[c].type == PrimitiveType::Plane)
      item = oriented_plane(c, points[c]);
    else if (primitives[c].type == PrimitiveType::Cylinder)
      item = oriented_cylinder(c, primitives[c], points[c]);
    if (item && std::isfinite(item->variance) && item->variance > 0) items.push_back(*item);
  }
  return items;
}

// Each group's coplanar sets (returned, per group) and coaxial sets, found before the directions
// are made orthogonal: each set counts as one plane or one line in its group's direction, which
// is formed again when one does.
std::vector<std::vector<std::vector<std::size_t>>> count_sets_as_one(
    std::vector<DirectionGroup>& groups, const std::vector<Oriented>& items,
    const std::vector<Primitive>& primitives, const std::vector<std::vector<Vec3>>& points,
    const std::vector<std::vector<double>>& weights, const RegularityOptions& options) {
  std::vector<std::vector<std::vector<std::size_t>>> coplanar(groups.size());
  const auto is_plane = [&](std::size_t i) {
    return primitives[items[i].cluster].type == PrimitiveType::Plane;
  };
  for (std::size_t g = 0; g < groups.size(); ++g) {
    DirectionGroup& group = groups[g];
    if (group.members.size() < 2) continue;
    bool counted = false;
    std::vector<AlignedPlane> planes;
    if (options.coplanar &&
        std::count_if(group.members.begin(), group.members.end(), is_plane) >= 2)
      for (const std::size_t i : group.members) {
        const std::size_t c = items[i].cluster;
        if (primitives[c].type != PrimitiveType::Plane) continue;
        if (const std::optional<AlignedPlane> plane =
                aligned_plane(c, group.direction, points[c], weights[c]))
          planes.push_back(*plane);
      }
    if (planes.size() >= 2) {
      coplanar[g] = coplanar_sets(group.covariance, std::move(planes), options);
      counted = count_coplanar_as_one(group, items, coplanar[g], points);
    }
    if (count_coaxial_as_one(group, items, primitives, points, weights, options)) counted = true;
    if (!counted) continue;
    const Eigen::Vector3d before = group.direction;
    form_direction(group);
    if (group.direction.dot(before) < 0) group.direction = -group.direction;
  }
  return coplanar;
}

// Refits every member of each group of two or more (or in a right angle) with the group's
// direction, then its coplanar sets with one plane and its cylinders on their shared lines. Adds
// the parallel, coplanar and coaxial relations; returns the clusters each group refitted, in
// increasing order, for the right angles and the relations after.
std::vector<std::vector<std::size_t>> align_groups(
    const std::vector<DirectionGroup>& groups, const std::vector<bool>& constrained,
    const std::vector<std::vector<std::vector<std::size_t>>>& coplanar,
    const std::vector<Oriented>& items, const RegularityOptions& options,
    std::vector<Primitive>& primitives, const std::vector<std::vector<Vec3>>& points,
    const std::vector<std::vector<double>>& weights, std::vector<Relation>& relations,
    SettledSurfaces& settled) {
  std::vector<std::vector<std::size_t>> refitted(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const DirectionGroup& group = groups[g];
    if (group.members.size() < 2 && !constrained[g]) continue;
    std::vector<AlignedCylinder> cylinders;
    Relation parallel;
    for (const std::size_t i : group.members) {
      const std::size_t c = items[i].cluster;
      Primitive& primitive = primitives[c];
      if (primitive.type == PrimitiveType::Plane) {
        if (align_plane(primitive, group.direction, points[c], weights[c]))
          parallel.members.push_back(c);
        continue;
      }
      if (std::optional<AlignedCylinder> cylinder =
              aligned_cylinder(c, primitive, group.direction, points, weights)) {
        cylinders.push_back(std::move(*cylinder));
        parallel.members.push_back(c);
      }
    }
    std::sort(parallel.members.begin(), parallel.members.end());
    refitted[g] = parallel.members;
    if (parallel.members.size() >= 2) relations.push_back(std::move(parallel));
    for (const std::vector<std::size_t>& set : coplanar[g])
      share_one_plane(group.direction, set, primitives, weights, relations);
    align_cylinders(group.direction, group.covariance, std::move(cylinders), options, primitives,
                    points, weights, relations, settled);
  }
  return refitted;
}

// Adds to `settled` the surfaces no direction relation refitted, for the radii and the spheres'
// centres: each such cylinder on its own axis (fitted again with it, for its radius's
// uncertainty; written back only if it joins a relation), and every sphere, fitted again alone.
void settle_the_others(const std::vector<Oriented>& items, const std::vector<Primitive>& primitives,
                       const std::vector<std::vector<Vec3>>& points,
                       const std::vector<std::vector<double>>& weights, SettledSurfaces& settled) {
  std::vector<bool> is_settled(primitives.size(), false);
  for (const SettledSurfaces::Surface& surface : settled.surfaces)
    is_settled[surface.cluster] = true;
  for (const Oriented& item : items) {
    const std::size_t c = item.cluster;
    if (primitives[c].type != PrimitiveType::Cylinder || is_settled[c]) continue;
    if (const std::optional<CoaxialFit> fit =
            fit_alone(primitives[c], item.direction, points[c], weights[c])) {
      settled.surfaces.push_back({c, false, settled.lines.size(), 0, fit->radii[0],
                                  fit->radius_variances[0], fit->rms[0]});
      settled.lines.push_back({item.direction, fit->centre, fit->centre_covariance, kNoRelation,
                               middle_along(item.direction, {&c, 1}, points, weights),
                               item.covariance});
    }
  }
  for (std::size_t c = 0; c < primitives.size(); ++c) {
    if (primitives[c].type != PrimitiveType::Sphere || points[c].empty()) continue;
    const Eigen::Vector3d centre = to_eigen(primitives[c].point);
    const SphereTerm term{points[c], weights[c], 0};
    if (const std::optional<JointFit> fit = fit_cylinders_and_spheres(
            {}, {}, {&centre, 1}, {&primitives[c].radius, 1}, {}, {&term, 1}, true)) {
      settled.surfaces.push_back({c, true, kNoLine, settled.centres.size(), fit->radii[0],
                                  fit->covariance(3, 3), fit->rms[0]});
      settled.centres.push_back(fit->sphere_centres[0]);
      settled.centre_covariances.emplace_back(fit->covariance.topLeftCorner<3, 3>());
    }
  }
}

// One orthogonal relation per pair of groups at right angles that both refitted a cluster: the
// group of the lower cluster first, the relations in the order of their clusters.
std::vector<Relation> right_angle_relations(
    const std::vector<std::pair<std::size_t, std::size_t>>& orthogonal,
    const std::vector<std::vector<std::size_t>>& refitted) {
  std::vector<Relation> right_angles;
  for (const auto& [i, j] : orthogonal) {
    if (refitted[i].empty() || refitted[j].empty()) continue;
    Relation& relation = right_angles.emplace_back();
    relation.kind = Relation::Kind::Orthogonal;
    const bool swap = refitted[j].front() < refitted[i].front();
    relation.members = swap ? refitted[j] : refitted[i];
    relation.others = swap ? refitted[i] : refitted[j];
  }
  std::sort(right_angles.begin(), right_angles.end(), [](const Relation& a, const Relation& b) {
    return std::tie(a.members, a.others) < std::tie(b.members, b.others);
  });
  return right_angles;
}

}  // namespace

std::vector<Relation> regularize(std::vector<Primitive>& primitives,
                                 const std::vector<std::vector<Vec3>>& points,
                                 const std::vector<std::vector<double>>& weights,
                                 const RegularityOptions& options) {
  const std::vector<Oriented> items = oriented_items(primitives, points);
  std::vector<DirectionGroup> groups = group_directions(items, options);
  std::vector<std::vector<std::vector<std::size_t>>> coplanar =
      count_sets_as_one(groups, items, primitives, points, weights, options);
  std::vector<std::pair<std::size_t, std::size_t>> orthogonal;
  if (options.orthogonal) {
    orthogonal = orthogonalize(groups, options);
    merge_parallel_groups(groups, orthogonal, coplanar);
  }
  std::vector<bool> constrained(groups.size(), false);
  for (const auto& [i, j] : orthogonal) constrained[i] = constrained[j] = true;
  std::vector<Relation> relations;
  SettledSurfaces settled;
  const std::vector<std::vector<std::size_t>> refitted =
      align_groups(groups, constrained, coplanar, items, options, primitives, points, weights,
                   relations, settled);
  if (options.equal_radii || options.spheres_on_axes || options.concentric) {
    settle_the_others(items, primitives, points, weights, settled);
    if (options.spheres_on_axes) {
      centre_spheres_on_axes(settled, options, primitives, points, weights, relations);
      line_up_spheres(settled, groups, refitted, options, primitives, points, weights, relations);
    }
    if (options.concentric)
      make_concentric(settled, options, primitives, points, weights, relations);
    if (options.equal_radii)
      equalize_radii(settled, options, primitives, points, weights, relations);
  }
  std::vector<Relation> tangents;
  if (options.tangency)
    make_tangent(groups, orthogonal, refitted, options, primitives, points, weights, relations,
                 tangents);
  const std::vector<Relation> right_angles = right_angle_relations(orthogonal, refitted);
  relations.insert(relations.end(), right_angles.begin(), right_angles.end());
  relations.insert(relations.end(), tangents.begin(), tangents.end());
  return relations;
}

void sort_relations(std::vector<ClusterRelation>& relations) {
  std::sort(relations.begin(), relations.end(), [](const auto& a, const auto& b) {
    return a.kind != b.kind           ? a.kind < b.kind
           : a.clusters != b.clusters ? a.clusters < b.clusters
                                      : a.orthogonal_to < b.orthogonal_to;
  });
}

void keep_inliers(const Primitive& primitive, std::span<const Vec3> points,
                  std::span<const double> weights, double threshold, double floor,
                  std::vector<Vec3>& kept_points, std::vector<double>& kept_weights) {
  std::vector<double> residuals;
  residuals.reserve(points.size());
  for (const Vec3& p : points) residuals.push_back(primitive.distance(p));
  std::vector<double> sorted = residuals;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double limit = std::max(threshold * 1.4826 * sorted[sorted.size() / 2], floor);
  kept_points.clear();
  kept_weights.clear();
  for (std::size_t i = 0; i < points.size(); ++i)
    if (residuals[i] <= limit) {
      kept_points.push_back(points[i]);
      kept_weights.push_back(weights[i]);
    }
}

std::vector<ClusterRelation> regularize_kept(std::vector<Primitive>& primitives,
                                             const std::vector<std::vector<Vec3>>& inlier_points,
                                             const std::vector<std::vector<double>>& inlier_weights,
                                             const RegularityOptions& options) {
  const std::vector<Primitive> own = primitives;
  std::vector<ClusterRelation> relations;
  for (const Relation& relation : regularize(primitives, inlier_points, inlier_weights, options)) {
    ClusterRelation& related = relations.emplace_back();
    related.kind = relation.kind;
    for (const std::size_t c : relation.members)
      related.clusters.push_back(static_cast<std::uint32_t>(c));
    for (const std::size_t c : relation.others)
      related.orthogonal_to.push_back(static_cast<std::uint32_t>(c));
    related.deviation = deviation(related, own, primitives);
  }
  sort_relations(relations);
  return relations;
}

std::vector<ClusterRelation> regularize_inliers(std::vector<Primitive>& primitives,
                                                const std::vector<std::vector<Vec3>>& points,
                                                const std::vector<std::vector<double>>& weights,
                                                double outlier_threshold, double floor,
                                                const RegularityOptions& options) {
  std::vector<std::vector<Vec3>> inlier_points(primitives.size());
  std::vector<std::vector<double>> inlier_weights(primitives.size());
  for (std::size_t c = 0; c < primitives.size(); ++c)
    if (!points[c].empty())
      keep_inliers(primitives[c], points[c], weights[c], outlier_threshold, floor, inlier_points[c],
                   inlier_weights[c]);
  return regularize_kept(primitives, inlier_points, inlier_weights, options);
}

}  // namespace primseg::detail
