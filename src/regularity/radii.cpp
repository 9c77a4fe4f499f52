// Spheres centred on axis lines, lines of spheres, and cylinders and spheres of one radius.
#include "regularity/stages.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "eigen_conversions.hpp"
#include "orthonormal_pair.hpp"
#include "symmetric_eigen2.hpp"

namespace primseg::detail {

namespace {

// The largest variance of a position of covariance `covariance`: in its worst direction.
template <int D>
double largest_variance(const Eigen::Matrix<double, D, D>& covariance) {
  if constexpr (D == 1) {
    return covariance(0, 0);
  } else if constexpr (D == 2) {
    return larger_eigenvalue(covariance);
  } else {
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>>(covariance,
                                                                      Eigen::EigenvaluesOnly)
        .eigenvalues()(D - 1);
  }
}

// Whether a position of covariance `covariance` is known to within `bound` at the significance,
// in its worst direction (the interval rule of the spheres' centres).
template <int D>
bool known_within(const Eigen::Matrix<double, D, D>& covariance, double significance,
                  double bound) {
  return significance * std::sqrt(largest_variance(covariance)) <= bound;
}

// Whether the offset `offset` of covariance `covariance` is within the χ² bound `bound`.
template <int D>
bool within_chi_square(const Eigen::Matrix<double, D, 1>& offset,
                       const Eigen::Matrix<double, D, D>& covariance, double bound) {
  if constexpr (D == 1)
    return offset(0) * offset(0) <= bound * covariance(0, 0);
  else
    return offset.dot(covariance.ldlt().solve(offset)) <= bound;
}

// A sphere's centre in D coordinates (along a line, across one, in space), for pool_centres().
template <int D>
struct PlacedCentre {
  std::size_t surface = 0;  // index into settled.surfaces
  Eigen::Matrix<double, D, 1> position;
  Eigen::Matrix<double, D, D> covariance;
};

// A set of spheres whose centres agree, and their information-weighted position.
template <int D>
struct CentreSet {
  std::vector<std::size_t> surfaces;  // indices into settled.surfaces, the first best located
  PooledPosition<D> pooled;
};

// The spheres `placed` in sets whose centres are one position within the significance. Best
// located first (the least trace of covariance), each joins the first set whose pooled position
// it is within max_radius_difference of its radius of and, with the covariance of both plus
// `extra(first, k)` (first the set's first surface, k its own), within the χ² bound of D degrees
// of freedom, or within the length tolerance. A centre whose significance interval is wider than
// that radius bound (the interval rule of the centres) is a set of its own. Returns every set, in
// the order they formed, those of one centre known less well last.
template <int D, class ExtraCovariance>
std::vector<CentreSet<D>> pool_centres(const SettledSurfaces& settled,
                                       std::vector<PlacedCentre<D>> placed,
                                       const RegularityOptions& options,
                                       const ExtraCovariance& extra) {
  const double bound = chi_square_bound(options.significance, D);
  const auto largest_offset = [&](std::size_t k) {
    return options.max_radius_difference * settled.surfaces[k].radius;
  };
  std::vector<CentreSet<D>> unplaced;
  std::erase_if(placed, [&](const PlacedCentre<D>& sphere) {
    if (known_within(sphere.covariance, options.significance, largest_offset(sphere.surface)))
      return false;
    unplaced.emplace_back().surfaces.push_back(sphere.surface);
    return true;
  });
  std::stable_sort(placed.begin(), placed.end(),
                   [](const PlacedCentre<D>& a, const PlacedCentre<D>& b) {
                     return a.covariance.trace() < b.covariance.trace();
                   });
  std::vector<CentreSet<D>> sets;
  for (const PlacedCentre<D>& sphere : placed) {
    std::size_t joined = sets.size();
    for (std::size_t s = 0; s < sets.size() && joined == sets.size(); ++s) {
      const Eigen::Matrix<double, D, 1> offset = sphere.position - sets[s].pooled.centre();
      // Most pairs end here, before any covariance.
      if (!(offset.norm() <= largest_offset(sphere.surface))) continue;
      const Eigen::Matrix<double, D, D> combined = sphere.covariance + sets[s].pooled.covariance() +
                                                   extra(sets[s].surfaces[0], sphere.surface);
      if (within_chi_square(offset, combined, bound) ||
          within_tolerance(offset.norm(), options.length_tolerance))
        joined = s;
    }
    if (joined == sets.size()) sets.emplace_back();
    sets[joined].surfaces.push_back(sphere.surface);
    sets[joined].pooled.add(sphere.position, sphere.covariance);
  }
  sets.insert(sets.end(), unplaced.begin(), unplaced.end());
  return sets;
}

// No covariance beyond the centres' own.
template <int D>
auto no_extra_covariance() {
  return [](std::size_t, std::size_t) { return Eigen::Matrix<double, D, D>::Zero().eval(); };
}

// The spheres `spheres` (indices into settled.surfaces) grouped by their places along
// `direction` (pool_centres() of one degree of freedom, each place's variance that of its own
// fit's centre along the direction).
std::vector<std::vector<std::size_t>> places_along(const SettledSurfaces& settled,
                                                   std::span<const std::size_t> spheres,
                                                   const Eigen::Vector3d& direction,
                                                   const RegularityOptions& options) {
  std::vector<PlacedCentre<1>> placed;
  for (const std::size_t k : spheres) {
    const std::size_t centre = settled.surfaces[k].centre;
    placed.push_back({k, Eigen::Matrix<double, 1, 1>(direction.dot(settled.centres[centre])),
                      Eigen::Matrix<double, 1, 1>(
                          direction.dot(settled.centre_covariances[centre] * direction))});
  }
  std::vector<std::vector<std::size_t>> groups;
  for (CentreSet<1>& set :
       pool_centres(settled, std::move(placed), options, no_extra_covariance<1>()))
    groups.push_back(std::move(set.surfaces));
  return groups;
}

// Line l fitted with the surfaces `cylinders` and `spheres` on it (indices into
// settled.surfaces), each with its own radius, sphere j on centre centre_of[j], started from
// centres[centre_of[j]]: fit_cylinders_and_spheres() with its covariance.
std::optional<JointFit> fit_line(const SettledSurfaces& settled, std::size_t l,
                                 std::span<const std::size_t> cylinders,
                                 std::span<const std::size_t> spheres,
                                 std::span<const std::size_t> centre_of,
                                 std::span<const Eigen::Vector3d> centres,
                                 const std::vector<std::vector<Vec3>>& points,
                                 const std::vector<std::vector<double>>& weights) {
  std::vector<CylinderTerm> terms;
  std::vector<SphereTerm> sphere_terms;
  std::vector<double> radii;
  for (const std::size_t k : cylinders) {
    const std::size_t c = settled.surfaces[k].cluster;
    terms.push_back({points[c], weights[c], 0, radii.size()});
    radii.push_back(settled.surfaces[k].radius);
  }
  for (std::size_t j = 0; j < spheres.size(); ++j) {
    const std::size_t c = settled.surfaces[spheres[j]].cluster;
    sphere_terms.push_back({points[c], weights[c], radii.size(), 0, centre_of[j]});
    radii.push_back(settled.surfaces[spheres[j]].radius);
  }
  const SettledSurfaces::Line& line = settled.lines[l];
  return fit_cylinders_and_spheres({&line.direction, 1}, {&line.centre, 1}, centres, radii, terms,
                                   sphere_terms, true);
}

// Writes fit_line()'s `fit` back: the line, its cylinders and its spheres (each then on line l),
// with their radii's variances, and their primitives.
void write_line(SettledSurfaces& settled, std::size_t l, std::span<const std::size_t> cylinders,
                std::span<const std::size_t> spheres, std::span<const std::size_t> centre_of,
                const JointFit& fit, std::vector<Primitive>& primitives) {
  SettledSurfaces::Line& line = settled.lines[l];
  const Eigen::Index first_radius = 2 + static_cast<Eigen::Index>(fit.sphere_centres.size());
  line.centre = fit.centres[0];
  line.covariance = fit.covariance.topLeftCorner<2, 2>();
  for (std::size_t j = 0; j < cylinders.size() + spheres.size(); ++j) {
    const bool is_sphere = j >= cylinders.size();
    SettledSurfaces::Surface& surface =
        settled.surfaces[is_sphere ? spheres[j - cylinders.size()] : cylinders[j]];
    const Eigen::Index q = static_cast<Eigen::Index>(j);
    surface.radius = fit.radii[j];
    surface.radius_variance = fit.covariance(first_radius + q, first_radius + q);
    surface.rms = fit.rms[j];
    Primitive& primitive = primitives[surface.cluster];
    if (is_sphere) {
      surface.line = l;
      settled.centres[surface.centre] = fit.sphere_centres[centre_of[j - cylinders.size()]];
      primitive.point = to_vec3(settled.centres[surface.centre]);
      primitive.radius = surface.radius;
    } else {
      place_cylinder(primitive, line.direction, line.centre, surface.radius);
    }
  }
}

// The factor by which the bound of sphere k's residual rise on line l is scaled, for the line's
// held direction. At the height h of the sphere's centre along the line, from where its cylinders
// are, the line is misplaced by the direction's tilt times h, of covariance h² T, which its joint
// fit cannot correct: a centre held on it rises by tr(C⁻¹ h² T) σ² more on average than the 2σ²
// of the two coordinates it loses, C the covariance of the sphere's own centre across the line.
// The bound is scaled by that mean, 1 + tr(C⁻¹ h² T) / 2, at most 2: beyond, the tilt would place
// the line less well than the sphere's own centre is known, and the held direction rather than
// the sphere would decide. 1 when C is singular.
double tilt_allowance(const SettledSurfaces& settled, std::size_t l, std::size_t k) {
  const SettledSurfaces::Line& line = settled.lines[l];
  const std::size_t centre = settled.surfaces[k].centre;
  const Eigen::Matrix2d across = tilt_in_frame(line.direction, settled.centre_covariances[centre]);
  const double height = line.direction.dot(settled.centres[centre]) - line.middle;
  const Eigen::LDLT<Eigen::Matrix2d> solver(across);
  if (solver.info() != Eigen::Success || !(solver.vectorD().minCoeff() > 0)) return 1;
  const double added = (solver.solve(height * height * line.tilt)).trace();
  return std::isfinite(added) ? 1 + std::clamp(added, 0.0, 2.0) / 2 : 1;
}

// Surface `surface`'s residual_pull() on a joint fit in which its RMS is `joint_rms`.
double surface_pull(const SettledSurfaces::Surface& surface, double joint_rms,
                    const std::vector<std::vector<Vec3>>& points) {
  return residual_pull(surface.rms, joint_rms, points[surface.cluster].size());
}

// How line l's fit `fit` (none: it failed) explains its members, `cylinders` then `spheres`
// (indices into settled.surfaces), against their own fits: the largest residual_excess() at the
// significance corrected for their number (at least 1; infinite without a fit), a cylinder's own
// fit having 3 parameters and a sphere's `sphere_parameters`, of which the line takes
// `sphere_lost` (the cylinders, already on it, are held to one degree of freedom), sphere j's
// bound scaled by allowance(j), which sphere (an index into `spheres`) of those `may_leave`
// accepts has the largest (`worst`), and how many members fail.
template <class Allowance, class MayLeave>
GuardExcess line_excess(const SettledSurfaces& settled, std::span<const std::size_t> cylinders,
                        std::span<const std::size_t> spheres, const JointFit* fit,
                        int sphere_parameters, std::size_t sphere_lost, const Allowance& allowance,
                        const RegularityOptions& options,
                        const std::vector<std::vector<Vec3>>& points, const MayLeave& may_leave) {
  const std::size_t members = cylinders.size() + spheres.size();
  const double cylinder_bound = guard_bound(options.significance, members, 1);
  const double sphere_bound = guard_bound(options.significance, members, sphere_lost);
  GuardExcess result;
  for (std::size_t j = 0; j < members; ++j) {
    const bool is_sphere = j >= cylinders.size();
    const SettledSurfaces::Surface& surface =
        settled.surfaces[is_sphere ? spheres[j - cylinders.size()] : cylinders[j]];
    const double excess =
        fit ? residual_excess(
                  surface.rms, fit->rms[j], points[surface.cluster].size(),
                  is_sphere ? sphere_bound * allowance(j - cylinders.size()) : cylinder_bound,
                  is_sphere ? sphere_parameters : 3, options.length_tolerance)
            : std::numeric_limits<double>::infinity();
    result.add(excess, is_sphere ? j - cylinders.size() : 0,
               is_sphere && may_leave(j - cylinders.size()));
  }
  return result;
}

// The residual excesses (line_excess()) of line l refitted with its cylinders and `spheres`, each
// sphere with a centre of its own on it; nullopt for the fit when it fails.
struct SpheresOnLine {
  std::optional<JointFit> fit;
  GuardExcess excess;
};
SpheresOnLine spheres_on_line(const SettledSurfaces& settled, std::size_t l,
                              const std::vector<std::size_t>& cylinders,
                              const std::vector<std::size_t>& spheres,
                              const RegularityOptions& options,
                              const std::vector<std::vector<Vec3>>& points,
                              const std::vector<std::vector<double>>& weights) {
  std::vector<Eigen::Vector3d> centres;
  centres.reserve(spheres.size());
  for (const std::size_t k : spheres)
    centres.push_back(settled.centres[settled.surfaces[k].centre]);
  std::vector<std::size_t> own_centre(spheres.size());
  std::iota(own_centre.begin(), own_centre.end(), 0);
  SpheresOnLine result;
  result.fit = fit_line(settled, l, cylinders, spheres, own_centre, centres, points, weights);
  // A sphere's own fit has 4 parameters, 2 of which the line takes; any may leave.
  result.excess = line_excess(
      settled, cylinders, spheres, result.fit ? &*result.fit : nullptr, 4, 2,
      [&](std::size_t j) { return tilt_allowance(settled, l, spheres[j]); }, options, points,
      [](std::size_t) { return true; });
  return result;
}

// Refits line l with its cylinders and the spheres `spheres` (indices into settled.surfaces) on
// it, each sphere one parameter along it: while any member's residual sum rises by more than the
// significance, corrected for the number of members, allows, a sphere leaves
// (member_that_leaves(): couplingdown's ten spheres on its z axis left one by one, at 48 clusters
// beside a sphere piece fitted at 4.3e-4, when the sphere of the largest own excess left). Writes
// the line, its members and their primitives back, and adds the spheres to the line's coaxial
// relation (started when it has none), unless fewer spheres than `fewest` stay. Returns whether it
// did.
bool settle_on_line(SettledSurfaces& settled, std::size_t l,
                    const std::vector<std::size_t>& cylinders, std::vector<std::size_t> spheres,
                    const RegularityOptions& options, std::vector<Primitive>& primitives,
                    const std::vector<std::vector<Vec3>>& points,
                    const std::vector<std::vector<double>>& weights,
                    std::vector<Relation>& relations, std::size_t fewest = 1) {
  std::vector<SettledSurfaces::Surface>& surfaces = settled.surfaces;
  std::optional<JointFit> fit;
  if (spheres.size() < fewest) return false;
  // The fit of the spheres left: after a sphere leaves, the one made while choosing it.
  SpheresOnLine all = spheres_on_line(settled, l, cylinders, spheres, options, points, weights);
  while (true) {
    if (!(all.excess.largest > 1)) {
      fit = std::move(all.fit);
      break;
    }
    auto [leaving, without_leaving] = member_that_leaves(
        every_member(spheres.size()), all.excess.worst,
        [&](std::size_t j) {
          return all.fit ? surface_pull(surfaces[spheres[j]], all.fit->rms[cylinders.size() + j],
                                        points)
                         : std::numeric_limits<double>::quiet_NaN();
        },
        [&](std::size_t j) {
          std::vector<std::size_t> others = spheres;
          others.erase(others.begin() + static_cast<std::ptrdiff_t>(j));
          return spheres_on_line(settled, l, cylinders, others, options, points, weights);
        });
    spheres.erase(spheres.begin() + static_cast<std::ptrdiff_t>(leaving));
    if (spheres.size() < fewest) break;
    all = std::move(without_leaving);
  }
  if (!fit) return false;
  std::vector<std::size_t> own_centre(spheres.size());  // a centre each
  std::iota(own_centre.begin(), own_centre.end(), 0);
  write_line(settled, l, cylinders, spheres, own_centre, *fit, primitives);
  std::vector<std::size_t> members;
  members.reserve(cylinders.size() + spheres.size());
  for (const std::size_t k : cylinders) members.push_back(surfaces[k].cluster);
  for (const std::size_t k : spheres) members.push_back(surfaces[k].cluster);
  SettledSurfaces::Line& line = settled.lines[l];
  if (line.coaxial == kNoRelation) {
    line.coaxial = relations.size();
    relations.push_back({Relation::Kind::Coaxial, {}, {}});
  }
  std::vector<std::size_t>& coaxial = relations[line.coaxial].members;
  coaxial.insert(coaxial.end(), members.begin(), members.end());
  std::sort(coaxial.begin(), coaxial.end());
  coaxial.erase(std::unique(coaxial.begin(), coaxial.end()), coaxial.end());
  return true;
}

}  // namespace

void centre_spheres_on_axes(SettledSurfaces& settled, const RegularityOptions& options,
                            std::vector<Primitive>& primitives,
                            const std::vector<std::vector<Vec3>>& points,
                            const std::vector<std::vector<double>>& weights,
                            std::vector<Relation>& relations) {
  std::vector<SettledSurfaces::Surface>& surfaces = settled.surfaces;
  const std::size_t line_count = settled.lines.size();
  std::vector<std::vector<std::size_t>> cylinders_on(line_count), spheres_on(line_count);
  std::vector<double> smallest_radius(line_count, std::numeric_limits<double>::infinity());
  for (std::size_t k = 0; k < surfaces.size(); ++k)
    if (!surfaces[k].sphere) {
      cylinders_on[surfaces[k].line].push_back(k);
      smallest_radius[surfaces[k].line] =
          std::min(smallest_radius[surfaces[k].line], surfaces[k].radius);
    }
  // An offset is two normals: the bound they exceed as rarely as one normal the significance.
  const double significance = options.significance;
  const double offset_bound = chi_square_bound(significance, 2);
  // Each line's frame (orthonormal_pair(direction) as rows), or none when it is not placed well
  // enough to hold a sphere.
  std::vector<std::optional<Eigen::Matrix<double, 2, 3>>> frames(line_count);
  for (std::size_t l = 0; l < line_count; ++l) {
    const SettledSurfaces::Line& line = settled.lines[l];
    if (!(std::sqrt(line.covariance.trace()) < smallest_radius[l])) continue;
    const auto [u, v] = orthonormal_pair(line.direction);
    frames[l].emplace();
    *frames[l] << u.transpose(), v.transpose();
  }
  for (std::size_t k = 0; k < surfaces.size(); ++k) {
    const SettledSurfaces::Surface& sphere = surfaces[k];
    if (!sphere.sphere) continue;
    const Eigen::Vector3d& centre = settled.centres[sphere.centre];
    const Eigen::Matrix3d& covariance = settled.centre_covariances[sphere.centre];
    const double largest_offset = options.max_radius_difference * sphere.radius;
    std::size_t nearest = line_count;
    double nearest_score = offset_bound;
    for (std::size_t l = 0; l < line_count; ++l) {
      if (!frames[l]) continue;
      const SettledSurfaces::Line& line = settled.lines[l];
      const Eigen::Matrix<double, 2, 3>& frame = *frames[l];
      const Eigen::Vector2d offset = frame * centre - line.centre;
      if (!(offset.norm() <= largest_offset)) continue;
      const double height = line.direction.dot(centre) - line.middle;
      const Eigen::Matrix2d combined =
          frame * covariance * frame.transpose() + line.covariance + height * height * line.tilt;
      if (!known_within(combined, significance, largest_offset)) continue;
      const double score = tolerated(offset.dot(combined.ldlt().solve(offset)), offset_bound,
                                     offset.norm(), options.length_tolerance);
      if (score <= nearest_score) {
        nearest_score = score;
        nearest = l;
      }
    }
    if (nearest < line_count) spheres_on[nearest].push_back(k);
  }
  for (std::size_t l = 0; l < line_count; ++l)
    if (!spheres_on[l].empty())
      settle_on_line(settled, l, cylinders_on[l], spheres_on[l], options, primitives, points,
                     weights, relations);
}

namespace {

// The fewest spheres that make a line with no cylinder. Two centres fall on a line of one of the
// design directions by chance on freeform parts (bunny00's default level with `--refine 2`: 30
// pairs among its 39 directions, mech-holes-shark's 10; and 1 and 0 sets of three or more).
constexpr std::size_t kFewestSpheresOnALine = 3;

}  // namespace

void line_up_spheres(SettledSurfaces& settled, const std::vector<DirectionGroup>& groups,
                     const std::vector<std::vector<std::size_t>>& refitted,
                     const RegularityOptions& options, std::vector<Primitive>& primitives,
                     const std::vector<std::vector<Vec3>>& points,
                     const std::vector<std::vector<double>>& weights,
                     std::vector<Relation>& relations) {
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (refitted[g].empty()) continue;
    const Eigen::Vector3d& direction = groups[g].direction;
    const auto [u, v] = orthonormal_pair(direction);
    Eigen::Matrix<double, 2, 3> frame;
    frame << u.transpose(), v.transpose();
    const Eigen::Matrix2d tilt = tilt_in_frame(direction, groups[g].covariance);
    std::vector<PlacedCentre<2>> placed;
    for (std::size_t k = 0; k < settled.surfaces.size(); ++k) {
      const SettledSurfaces::Surface& sphere = settled.surfaces[k];
      if (!sphere.sphere || sphere.line != kNoLine) continue;
      placed.push_back({k, frame * settled.centres[sphere.centre],
                        frame * settled.centre_covariances[sphere.centre] * frame.transpose()});
    }
    const auto height = [&](std::size_t k) {
      return direction.dot(settled.centres[settled.surfaces[k].centre]);
    };
    // The direction's tilt over the distance along it from the set's first member.
    const auto tilted = [&](std::size_t first, std::size_t k) -> Eigen::Matrix2d {
      const double apart = height(k) - height(first);
      return apart * apart * tilt;
    };
    for (const CentreSet<2>& set : pool_centres(settled, std::move(placed), options, tilted)) {
      // Three places along the line at least: spheres of one place (fragments of one sphere, a
      // ball and its socket) are on a line of any direction, and concentric instead.
      if (set.surfaces.size() < kFewestSpheresOnALine ||
          places_along(settled, set.surfaces, direction, options).size() < kFewestSpheresOnALine)
        continue;
      std::vector<std::size_t> clusters;
      for (const std::size_t k : set.surfaces) clusters.push_back(settled.surfaces[k].cluster);
      settled.lines.push_back({direction, set.pooled.centre(), set.pooled.covariance(), kNoRelation,
                               middle_along(direction, clusters, points, weights), tilt});
      if (!settle_on_line(settled, settled.lines.size() - 1, {}, set.surfaces, options, primitives,
                          points, weights, relations, kFewestSpheresOnALine))
        settled.lines.pop_back();
    }
  }
}

namespace {

// Classes of radii that are one radius within the significance: in increasing order of radius,
// a class grows while its radii stay consistent with their information-weighted mean (their χ²
// about it within chi_square_bound of its degrees of freedom) and its smallest within
// max_radius_difference of its largest (relative to the largest). A radius whose significance
// interval is wider than that bound joins none: any two such radii within the bound would pass, so
// the bound and not the data would decide (cylinder patches of a freeform surface; a nearly flat
// cylinder). Returns each surface's class.
std::vector<std::size_t> radius_classes(const std::vector<SettledSurfaces::Surface>& surfaces,
                                        const RegularityOptions& options) {
  const std::size_t n = surfaces.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return surfaces[a].radius < surfaces[b].radius;
  });
  std::vector<std::size_t> class_of(n);
  std::size_t classes = 0, open = 0;
  // The open class: its first radius, and Σ 1/σ², Σ d/σ², Σ d²/σ² of its radii's differences d
  // from that first one (differences keep the sums exact on CAD radii known to 1e-9).
  double first = 0, information = 0, moment = 0, square = 0;
  std::size_t members = 0;
  for (const std::size_t k : order) {
    const double r = surfaces[k].radius, variance = surfaces[k].radius_variance;
    if (!(variance > 0) ||
        options.significance * std::sqrt(variance) > options.max_radius_difference * r) {
      class_of[k] = classes++;  // a class of its own
      continue;
    }
    const double d = r - first;
    const double joined_information = information + 1 / variance,
                 joined_moment = moment + d / variance, joined_square = square + d * d / variance;
    const double spread = joined_square - joined_moment * joined_moment / joined_information;
    if (members == 0 || r - first > options.max_radius_difference * r ||
        (spread > chi_square_bound(options.significance, members) &&
         !within_tolerance(r - first, options.length_tolerance))) {
      first = r;
      information = 1 / variance;
      moment = square = 0;
      members = 1;
      open = classes++;
      class_of[k] = open;
      continue;
    }
    information = joined_information;
    moment = joined_moment;
    square = joined_square;
    ++members;
    class_of[k] = open;
  }
  return class_of;
}

// The spheres `set` (indices into settled.surfaces) as members of a joint fit.
std::vector<CoaxialMember> sphere_members(const SettledSurfaces& settled,
                                          const std::vector<std::size_t>& set,
                                          const std::vector<std::vector<Vec3>>& points,
                                          const std::vector<std::vector<double>>& weights) {
  std::vector<CoaxialMember> members;
  for (const std::size_t k : set) {
    const SettledSurfaces::Surface& sphere = settled.surfaces[k];
    members.push_back({points[sphere.cluster], weights[sphere.cluster], sphere.radius});
  }
  return members;
}

// The spheres `set` (indices into settled.surfaces) refitted with one centre, and how it explains
// them against their own fits: their largest residual_excess() at the significance corrected for
// their number (at least 1; infinite without a fit), and whose it is (an index into `set`).
struct CentreOfSet {
  std::optional<ConcentricFit> fit;
  GuardExcess excess = GuardExcess::without_fit();
};
CentreOfSet centre_of_set(const SettledSurfaces& settled, const std::vector<std::size_t>& set,
                          const RegularityOptions& options,
                          const std::vector<std::vector<Vec3>>& points,
                          const std::vector<std::vector<double>>& weights) {
  PooledPosition<3> pooled;
  for (const std::size_t k : set) {
    const std::size_t centre = settled.surfaces[k].centre;
    pooled.add(settled.centres[centre], settled.centre_covariances[centre]);
  }
  CentreOfSet result;
  result.fit = fit_concentric(pooled.centre(), sphere_members(settled, set, points, weights));
  if (!result.fit) return result;
  // A sphere gives up its centre: 3 degrees of freedom.
  const double bound = guard_bound(options.significance, set.size(), 3);
  result.excess = {};
  for (std::size_t j = 0; j < set.size(); ++j) {
    const SettledSurfaces::Surface& sphere = settled.surfaces[set[j]];
    // A sphere's own fit has 4 parameters.
    result.excess.add(residual_excess(sphere.rms, result.fit->rms[j], points[sphere.cluster].size(),
                                      bound, 4, options.length_tolerance),
                      j);
  }
  return result;
}

// The spheres `set` refitted with one centre; while a member's residual sum rises by more than
// the significance, corrected for their number, allows, a member leaves `set`
// (member_that_leaves()). Nothing when fewer than two stay or a fit fails.
std::optional<ConcentricFit> one_centre(const SettledSurfaces& settled,
                                        std::vector<std::size_t>& set,
                                        const RegularityOptions& options,
                                        const std::vector<std::vector<Vec3>>& points,
                                        const std::vector<std::vector<double>>& weights) {
  if (set.size() < 2) return std::nullopt;
  // The fit of the spheres left: after a sphere leaves, the one made while choosing it.
  CentreOfSet all = centre_of_set(settled, set, options, points, weights);
  while (true) {
    if (!all.fit) return std::nullopt;
    if (!(all.excess.largest > 1)) return std::move(all.fit);
    if (set.size() == 2) return std::nullopt;  // one would stay
    auto [leaving, without_leaving] = member_that_leaves(
        every_member(set.size()), all.excess.worst,
        [&](std::size_t j) {
          return surface_pull(settled.surfaces[set[j]], all.fit->rms[j], points);
        },
        [&](std::size_t j) {
          std::vector<std::size_t> others = set;
          others.erase(others.begin() + static_cast<std::ptrdiff_t>(j));
          return centre_of_set(settled, others, options, points, weights);
        });
    set.erase(set.begin() + static_cast<std::ptrdiff_t>(leaving));
    all = std::move(without_leaving);
  }
}

// Refits the spheres `set` (indices into settled.surfaces) with one centre (one_centre()). Writes
// the centre, the radii and the primitives back and appends the Concentric relation, unless fewer
// than two stay.
void settle_concentric(SettledSurfaces& settled, std::vector<std::size_t> set,
                       const RegularityOptions& options, std::vector<Primitive>& primitives,
                       const std::vector<std::vector<Vec3>>& points,
                       const std::vector<std::vector<double>>& weights,
                       std::vector<Relation>& relations) {
  const std::optional<ConcentricFit> fit = one_centre(settled, set, options, points, weights);
  if (!fit) return;
  std::vector<SettledSurfaces::Surface>& surfaces = settled.surfaces;
  const std::size_t shared = surfaces[set[0]].centre;
  settled.centres[shared] = fit->centre;
  Relation& concentric = relations.emplace_back(Relation{Relation::Kind::Concentric, {}, {}});
  for (std::size_t j = 0; j < set.size(); ++j) {
    SettledSurfaces::Surface& sphere = surfaces[set[j]];
    sphere.centre = shared;
    sphere.radius = fit->radii[j];
    sphere.radius_variance = fit->radius_variances[j];
    sphere.rms = fit->rms[j];
    primitives[sphere.cluster].point = to_vec3(fit->centre);
    primitives[sphere.cluster].radius = sphere.radius;
    concentric.members.push_back(sphere.cluster);
  }
  std::sort(concentric.members.begin(), concentric.members.end());
}

// Line l refitted with its cylinders and spheres, the spheres of each of `sets` (those of two
// or more members) on one centre, and how it explains them (line_excess(), of which only a sphere
// of a set may leave): the sets, and for each sphere its centre's index in the fit.
struct SetsOnLine {
  std::vector<std::vector<std::size_t>> sets;
  std::vector<std::size_t> centre_of;
  std::optional<JointFit> fit;
  GuardExcess excess = GuardExcess::without_fit();
};
SetsOnLine sets_on_line(const SettledSurfaces& settled, std::size_t l,
                        const std::vector<std::size_t>& cylinders,
                        const std::vector<std::size_t>& spheres,
                        std::vector<std::vector<std::size_t>> sets,
                        const RegularityOptions& options,
                        const std::vector<std::vector<Vec3>>& points,
                        const std::vector<std::vector<double>>& weights) {
  const std::vector<SettledSurfaces::Surface>& surfaces = settled.surfaces;
  SetsOnLine result;
  std::erase_if(sets, [](const std::vector<std::size_t>& set) { return set.size() < 2; });
  result.sets = std::move(sets);
  if (result.sets.empty()) return result;
  // The sets' centres first, started from their first members', then one per other sphere.
  std::vector<Eigen::Vector3d> centres;
  std::map<std::size_t, std::size_t> set_centre;  // a set's surfaces: their centre's index
  for (const std::vector<std::size_t>& set : result.sets) {
    for (const std::size_t k : set) set_centre[k] = centres.size();
    centres.push_back(settled.centres[surfaces[set[0]].centre]);
  }
  result.centre_of.resize(spheres.size());
  for (std::size_t j = 0; j < spheres.size(); ++j) {
    const auto shared = set_centre.find(spheres[j]);
    result.centre_of[j] = shared != set_centre.end() ? shared->second : centres.size();
    if (shared == set_centre.end()) centres.push_back(settled.centres[surfaces[spheres[j]].centre]);
  }
  result.fit = fit_line(settled, l, cylinders, spheres, result.centre_of, centres, points, weights);
  // On the line a sphere has 2 parameters of its own (as fit_radii() counts), and a set shares
  // its place; only a sphere of a set may leave.
  result.excess = line_excess(
      settled, cylinders, spheres, result.fit ? &*result.fit : nullptr, 2, 1,
      [](std::size_t) { return 1.0; }, options, points,
      [&](std::size_t j) { return set_centre.contains(spheres[j]); });
  return result;
}

// Line l refitted with its cylinders and spheres, the spheres of each of `sets` on one centre
// (sets_on_line()): while a member's residual sum rises by more than the significance, corrected
// for the number of members, allows, a sphere of a set leaves it (member_that_leaves(); a set left
// with one member dissolves). Writes the line, its members and their primitives back and appends a
// Concentric relation per set, unless no set stays or a fit fails.
void share_centres_on_line(SettledSurfaces& settled, std::size_t l,
                           std::vector<std::vector<std::size_t>> sets,
                           const RegularityOptions& options, std::vector<Primitive>& primitives,
                           const std::vector<std::vector<Vec3>>& points,
                           const std::vector<std::vector<double>>& weights,
                           std::vector<Relation>& relations) {
  std::vector<SettledSurfaces::Surface>& surfaces = settled.surfaces;
  std::vector<std::size_t> cylinders, spheres;
  for (std::size_t k = 0; k < surfaces.size(); ++k)
    if (surfaces[k].line == l) (surfaces[k].sphere ? spheres : cylinders).push_back(k);
  // The fit of the sets left: after a sphere leaves, the one made while choosing it.
  SetsOnLine all =
      sets_on_line(settled, l, cylinders, spheres, std::move(sets), options, points, weights);
  while (true) {
    if (all.sets.empty() || !all.fit) return;
    if (!(all.excess.largest > 1)) break;
    std::vector<std::size_t> candidates;  // the spheres of the sets, whose centres come first
    for (std::size_t j = 0; j < spheres.size(); ++j)
      if (all.centre_of[j] < all.sets.size()) candidates.push_back(j);
    const auto without = [&](std::size_t j) {
      std::vector<std::vector<std::size_t>> fewer = all.sets;
      for (std::vector<std::size_t>& set : fewer) std::erase(set, spheres[j]);
      return fewer;
    };
    auto [leaving, without_leaving] = member_that_leaves(
        candidates, all.excess.worst,
        [&](std::size_t j) {
          return surface_pull(surfaces[spheres[j]], all.fit->rms[cylinders.size() + j], points);
        },
        [&](std::size_t j) {
          return sets_on_line(settled, l, cylinders, spheres, without(j), options, points, weights);
        });
    all = std::move(without_leaving);
  }
  write_line(settled, l, cylinders, spheres, all.centre_of, *all.fit, primitives);
  for (const std::vector<std::size_t>& set : all.sets) {
    Relation& concentric = relations.emplace_back(Relation{Relation::Kind::Concentric, {}, {}});
    for (const std::size_t k : set) {
      surfaces[k].centre = surfaces[set[0]].centre;
      concentric.members.push_back(surfaces[k].cluster);
    }
    std::sort(concentric.members.begin(), concentric.members.end());
  }
}

}  // namespace

void make_concentric(SettledSurfaces& settled, const RegularityOptions& options,
                     std::vector<Primitive>& primitives,
                     const std::vector<std::vector<Vec3>>& points,
                     const std::vector<std::vector<double>>& weights,
                     std::vector<Relation>& relations) {
  std::vector<PlacedCentre<3>> placed;
  for (std::size_t k = 0; k < settled.surfaces.size(); ++k) {
    const SettledSurfaces::Surface& sphere = settled.surfaces[k];
    if (sphere.sphere && sphere.line == kNoLine)
      placed.push_back(
          {k, settled.centres[sphere.centre], settled.centre_covariances[sphere.centre]});
  }
  for (const CentreSet<3>& set :
       pool_centres(settled, std::move(placed), options, no_extra_covariance<3>()))
    if (set.surfaces.size() >= 2)
      settle_concentric(settled, set.surfaces, options, primitives, points, weights, relations);
  std::vector<std::vector<std::size_t>> spheres_on(settled.lines.size());
  for (std::size_t k = 0; k < settled.surfaces.size(); ++k)
    if (settled.surfaces[k].sphere && settled.surfaces[k].line != kNoLine)
      spheres_on[settled.surfaces[k].line].push_back(k);
  for (std::size_t l = 0; l < settled.lines.size(); ++l) {
    std::vector<std::vector<std::size_t>> places =
        places_along(settled, spheres_on[l], settled.lines[l].direction, options);
    std::erase_if(places, [](const std::vector<std::size_t>& place) { return place.size() < 2; });
    if (!places.empty())
      share_centres_on_line(settled, l, std::move(places), options, primitives, points, weights,
                            relations);
  }
}

namespace {

// The surfaces linked by a class of radii (`class_of`), by an axis line or by a sphere centre,
// by union-find: each component's surfaces in increasing order, at the index of its root (the
// others empty).
std::vector<std::vector<std::size_t>> linked_components(const SettledSurfaces& settled,
                                                        const std::vector<std::size_t>& class_of) {
  const std::size_t n = settled.surfaces.size();
  std::vector<std::size_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](std::size_t k) {
    std::size_t top = k;
    while (parent[top] != top) top = parent[top];
    while (parent[k] != top) k = std::exchange(parent[k], top);
    return top;
  };
  auto join = [&](std::size_t& first, std::size_t k) {
    if (first == n)
      first = k;
    else
      parent[root(k)] = root(first);
  };
  std::vector<std::size_t> first_of_class(n, n), first_on_line(settled.lines.size(), n),
      first_of_centre(settled.centres.size(), n);
  for (std::size_t k = 0; k < n; ++k) {
    const SettledSurfaces::Surface& surface = settled.surfaces[k];
    join(first_of_class[class_of[k]], k);
    if (surface.line != kNoLine) join(first_on_line[surface.line], k);
    if (surface.sphere) join(first_of_centre[surface.centre], k);
  }
  std::vector<std::vector<std::size_t>> components(n);
  for (std::size_t k = 0; k < n; ++k) components[root(k)].push_back(k);
  return components;
}

// A component's joint fit, as fit_cylinders_and_spheres() takes it: its lines, spheres, sphere
// centres (concentric spheres share one) and radii (a class of two or more has one radius, started
// from its first member's), and each member's term, its index among the cylinder terms or among
// the spheres.
struct RadiusProblem {
  std::vector<CylinderTerm> terms;
  std::vector<SphereTerm> spheres;
  std::vector<Eigen::Vector3d> directions, sphere_centres;
  std::vector<Eigen::Vector2d> centres;
  std::vector<double> radii;
  std::vector<std::size_t> term_of;
};

// The numbers a component's lines, sphere centres and radii (by class) take in its joint fit,
// n (the number of surfaces) for none yet; radius_problem() resets only the component's own
// entries, so that many small components cost no more than one large one.
struct JointNumbering {
  std::vector<std::size_t> line, centre, radius_of_class;
};

RadiusProblem radius_problem(const SettledSurfaces& settled,
                             const std::vector<std::size_t>& component,
                             const std::vector<std::size_t>& class_of,
                             const std::vector<std::size_t>& class_size,
                             const std::vector<std::vector<Vec3>>& points,
                             const std::vector<std::vector<double>>& weights,
                             JointNumbering& numbering) {
  const std::size_t n = settled.surfaces.size();
  RadiusProblem problem;
  problem.term_of.resize(component.size());
  for (const std::size_t k : component) {
    const SettledSurfaces::Surface& surface = settled.surfaces[k];
    if (surface.line != kNoLine) numbering.line[surface.line] = n;
    if (surface.sphere) numbering.centre[surface.centre] = n;
    numbering.radius_of_class[class_of[k]] = n;
  }
  for (std::size_t j = 0; j < component.size(); ++j) {
    const SettledSurfaces::Surface& surface = settled.surfaces[component[j]];
    std::size_t& radius = numbering.radius_of_class[class_of[component[j]]];
    if (radius == n || class_size[class_of[component[j]]] < 2) {
      radius = problem.radii.size();
      problem.radii.push_back(surface.radius);
    }
    std::size_t line = kNoLine;
    if (surface.line != kNoLine) {
      line = numbering.line[surface.line];
      if (line == n) {
        line = numbering.line[surface.line] = problem.directions.size();
        problem.directions.push_back(settled.lines[surface.line].direction);
        problem.centres.push_back(settled.lines[surface.line].centre);
      }
    }
    if (surface.sphere) {
      std::size_t& centre = numbering.centre[surface.centre];
      if (centre == n) {
        centre = problem.sphere_centres.size();
        problem.sphere_centres.push_back(settled.centres[surface.centre]);
      }
      problem.term_of[j] = problem.spheres.size();
      problem.spheres.push_back(
          {points[surface.cluster], weights[surface.cluster], radius, line, centre});
      continue;
    }
    problem.term_of[j] = problem.terms.size();
    problem.terms.push_back({points[surface.cluster], weights[surface.cluster], line, radius});
  }
  return problem;
}

// A component's joint fit (radius_problem()), and how it explains the members of classes of two or
// more against their own fits: their largest residual_excess() at the significance corrected for
// their number (at least 1; infinite without a fit), and whose it is (an index into `component`).
struct RadiusFit {
  RadiusProblem problem;
  std::optional<JointFit> fit;
  GuardExcess excess = GuardExcess::without_fit();

  // The index of the component's member j among fit->rms.
  std::size_t term(const SettledSurfaces& settled, const std::vector<std::size_t>& component,
                   std::size_t j) const {
    return settled.surfaces[component[j]].sphere ? problem.terms.size() + problem.term_of[j]
                                                 : problem.term_of[j];
  }
};
RadiusFit fit_radii(const SettledSurfaces& settled, const std::vector<std::size_t>& component,
                    const std::vector<std::size_t>& class_of,
                    const std::vector<std::size_t>& class_size, const RegularityOptions& options,
                    const std::vector<std::vector<Vec3>>& points,
                    const std::vector<std::vector<double>>& weights, JointNumbering& numbering) {
  RadiusFit result;
  result.problem =
      radius_problem(settled, component, class_of, class_size, points, weights, numbering);
  const RadiusProblem& problem = result.problem;
  result.fit =
      fit_cylinders_and_spheres(problem.directions, problem.centres, problem.sphere_centres,
                                problem.radii, problem.terms, problem.spheres, false);
  if (!result.fit) return result;
  // One test per member: at the significance each, a plate of a hundred equal holes would lose
  // one in four times.
  const std::size_t tested = static_cast<std::size_t>(
      std::count_if(component.begin(), component.end(),
                    [&](std::size_t k) { return class_size[class_of[k]] >= 2; }));
  // A member of a class gives up its radius: 1 degree of freedom.
  const double bound = guard_bound(options.significance, tested, 1);
  result.excess = {};
  for (std::size_t j = 0; j < component.size(); ++j) {
    const SettledSurfaces::Surface& surface = settled.surfaces[component[j]];
    if (class_size[class_of[component[j]]] < 2) continue;
    // A sphere's own fit has 4 parameters (2 on a line), a cylinder's (on its direction) 3.
    const int parameters = !surface.sphere ? 3 : surface.line == kNoLine ? 4 : 2;
    result.excess.add(
        residual_excess(surface.rms, result.fit->rms[result.term(settled, component, j)],
                        points[surface.cluster].size(), bound, parameters,
                        options.length_tolerance),
        j);
  }
  return result;
}

// Surface k leaves its class for one of its own, under the first unused number; returns its class.
std::size_t leave_class(std::size_t k, std::vector<std::size_t>& class_of,
                        std::vector<std::size_t>& class_size) {
  const std::size_t left = class_of[k];
  --class_size[left];
  const auto free_class = std::find(class_size.begin(), class_size.end(), 0);
  class_of[k] = static_cast<std::size_t>(free_class - class_size.begin());
  *free_class = 1;
  return left;
}

// Writes the joint `fit` back: the members of classes of two or more, and the surfaces on their
// lines and the spheres on their centres; appends each class of two or more as an EqualRadius
// relation.
void write_equal_radii(const SettledSurfaces& settled, const std::vector<std::size_t>& component,
                       const std::vector<std::size_t>& class_of,
                       const std::vector<std::size_t>& class_size, const RadiusProblem& problem,
                       const JointFit& fit, std::vector<Primitive>& primitives,
                       std::vector<Relation>& relations) {
  const std::vector<SettledSurfaces::Surface>& surfaces = settled.surfaces;
  std::vector<bool> moved_line(settled.lines.size(), false),
      moved_centre(settled.centres.size(), false);
  for (const std::size_t k : component) {
    if (class_size[class_of[k]] < 2) continue;
    if (surfaces[k].line != kNoLine) moved_line[surfaces[k].line] = true;
    if (surfaces[k].sphere) moved_centre[surfaces[k].centre] = true;
  }
  std::map<std::size_t, std::vector<std::size_t>> members_of_class;
  for (std::size_t j = 0; j < component.size(); ++j) {
    const SettledSurfaces::Surface& surface = surfaces[component[j]];
    const bool member = class_size[class_of[component[j]]] >= 2;
    Primitive& primitive = primitives[surface.cluster];
    if (surface.sphere) {
      if (!member && !moved_centre[surface.centre] &&
          (surface.line == kNoLine || !moved_line[surface.line]))
        continue;
      const SphereTerm& term = problem.spheres[problem.term_of[j]];
      primitive.point = to_vec3(fit.sphere_centres[term.centre]);
      primitive.radius = fit.radii[term.radius];
    } else {
      if (!moved_line[surface.line]) continue;
      const CylinderTerm& term = problem.terms[problem.term_of[j]];
      place_cylinder(primitive, problem.directions[term.line], fit.centres[term.line],
                     fit.radii[term.radius]);
    }
    if (member) members_of_class[class_of[component[j]]].push_back(surface.cluster);
  }
  for (auto& [unused, members] : members_of_class) {
    Relation& relation = relations.emplace_back();
    relation.kind = Relation::Kind::EqualRadius;
    std::sort(members.begin(), members.end());
    relation.members = std::move(members);
  }
}

}  // namespace

void equalize_radii(const SettledSurfaces& settled, const RegularityOptions& options,
                    std::vector<Primitive>& primitives,
                    const std::vector<std::vector<Vec3>>& points,
                    const std::vector<std::vector<double>>& weights,
                    std::vector<Relation>& relations) {
  const std::size_t n = settled.surfaces.size();
  std::vector<std::size_t> class_of = radius_classes(settled.surfaces, options);
  std::vector<std::size_t> class_size(n, 0);
  for (const std::size_t q : class_of) ++class_size[q];
  JointNumbering numbering{std::vector<std::size_t>(settled.lines.size(), n),
                           std::vector<std::size_t>(settled.centres.size(), n),
                           std::vector<std::size_t>(n, n)};
  for (const std::vector<std::size_t>& component : linked_components(settled, class_of)) {
    if (std::none_of(component.begin(), component.end(),
                     [&](std::size_t k) { return class_size[class_of[k]] >= 2; }))
      continue;
    // While the joint fit explains a member worse than its own beyond the significance, a member
    // takes a class of its own (member_that_leaves()). The fit of the classes left: after a
    // member leaves, the one made while choosing it.
    RadiusFit all =
        fit_radii(settled, component, class_of, class_size, options, points, weights, numbering);
    while (all.fit) {
      if (!(all.excess.largest > 1)) {
        write_equal_radii(settled, component, class_of, class_size, all.problem, *all.fit,
                          primitives, relations);
        break;
      }
      std::vector<std::size_t> candidates;
      for (std::size_t j = 0; j < component.size(); ++j)
        if (class_size[class_of[component[j]]] >= 2) candidates.push_back(j);
      auto [leaving, without_leaving] = member_that_leaves(
          candidates, all.excess.worst,
          [&](std::size_t j) {
            return surface_pull(settled.surfaces[component[j]],
                                all.fit->rms[all.term(settled, component, j)], points);
          },
          [&](std::size_t j) {
            const std::size_t k = component[j];
            const std::size_t left = leave_class(k, class_of, class_size);
            RadiusFit without = fit_radii(settled, component, class_of, class_size, options, points,
                                          weights, numbering);
            class_size[class_of[k]] = 0;  // back
            class_of[k] = left;
            ++class_size[left];
            return without;
          });
      leave_class(component[leaving], class_of, class_size);
      all = std::move(without_leaving);
    }
  }
}

}  // namespace primseg::detail
