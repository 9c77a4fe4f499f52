// Axis lines: a direction group's cylinders refitted with its direction, those whose axes agree
// on one line.
#include "regularity/stages.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "eigen_conversions.hpp"
#include "orthonormal_pair.hpp"
#include "symmetric_eigen2.hpp"

namespace primseg::detail {

std::optional<AlignedCylinder> aligned_cylinder(std::size_t c, const Primitive& cylinder,
                                                const Eigen::Vector3d& direction,
                                                const std::vector<std::vector<Vec3>>& points,
                                                const std::vector<std::vector<double>>& weights) {
  std::optional<CoaxialFit> fit = fit_alone(cylinder, direction, points[c], weights[c]);
  if (!fit) return std::nullopt;
  return AlignedCylinder{c, std::move(*fit), middle_along(direction, {&c, 1}, points, weights)};
}

namespace {

// Sets of cylinders (indices into `cylinders`, sorted best-located first) whose axes are one line
// within `bound` (a χ² bound of the 2 coordinates of an axis's offset): each joins the first set
// whose information-weighted axis it is near, counting the direction's tilt (`tilt`, radians²,
// orthonormal_pair(direction) coordinates) over the distance along it from the set's first
// member, as the coplanar sets do; or within the length tolerance of it. An axis known less well
// than the radius (a nearly flat cylinder) joins none.
std::vector<std::vector<std::size_t>> coaxial_sets(const std::vector<AlignedCylinder>& cylinders,
                                                   const Eigen::Matrix2d& tilt, double bound,
                                                   double length_tolerance) {
  std::vector<std::vector<std::size_t>> sets;
  std::vector<PooledCentre> pooled;
  for (std::size_t k = 0; k < cylinders.size(); ++k) {
    const CoaxialFit& fit = cylinders[k].fit;
    std::size_t joined = sets.size();
    const bool located = std::sqrt(fit.centre_covariance.trace()) < fit.radii[0];
    for (std::size_t s = 0; located && s < sets.size(); ++s) {
      const Eigen::Matrix2d covariance = pooled[s].covariance();
      const Eigen::Vector2d delta = fit.centre - covariance * pooled[s].weighted;
      const double apart = cylinders[k].middle - cylinders[sets[s][0]].middle;
      const Eigen::Matrix2d combined = fit.centre_covariance + covariance + apart * apart * tilt;
      if (delta.dot(combined.ldlt().solve(delta)) <= bound ||
          within_tolerance(delta.norm(), length_tolerance)) {
        joined = s;
        break;
      }
    }
    if (joined == sets.size()) {
      sets.emplace_back();
      pooled.emplace_back();
    }
    sets[joined].push_back(k);
    pooled[joined].add(fit);
  }
  return sets;
}

// The coaxial sets of a direction group's cylinders (each refitted alone with `direction`, of
// tilt covariance `direction_covariance`; sorted here, best-located first), each with its joint
// fit (none for a lone cylinder): coaxial_sets(), then the joint fit `fit_set(set)` (an optional
// fit whose `rms` are its members', in the set's order) must explain each member as its own fit
// did, within the significance corrected for the number of members: while some member's residual
// sum rises by more than guard_bound() of the 2 degrees of freedom it loses times its residual
// variance, a member leaves the set (member_that_leaves()); those that leave a set are a set of
// their own, tested in turn.
template <class FitSet>
auto fit_coaxial_sets(const Eigen::Vector3d& direction, const Eigen::Matrix3d& direction_covariance,
                      std::vector<AlignedCylinder>& cylinders, const RegularityOptions& options,
                      const std::vector<std::vector<Vec3>>& points, const FitSet& fit_set) {
  const double significance = options.significance;
  using Fit = std::invoke_result_t<FitSet, const std::vector<std::size_t>&>;  // optional
  std::stable_sort(cylinders.begin(), cylinders.end(),
                   [](const AlignedCylinder& a, const AlignedCylinder& b) {
                     return a.fit.centre_covariance.trace() < b.fit.centre_covariance.trace();
                   });
  std::vector<std::vector<std::size_t>> sets =
      coaxial_sets(cylinders, tilt_in_frame(direction, direction_covariance),
                   chi_square_bound(significance, 2), options.length_tolerance);
  // A set's joint fit, and how it explains its members.
  struct Assessed {
    Fit fit;
    GuardExcess excess;
  };
  const auto assess = [&](const std::vector<std::size_t>& set) {
    Assessed result;
    result.fit = fit_set(set);
    // A member gives up its own axis line: 2 degrees of freedom.
    const double bound = guard_bound(significance, set.size(), 2);
    for (std::size_t j = 0; j < set.size(); ++j) {
      const AlignedCylinder& member = cylinders[set[j]];
      result.excess.add(result.fit ? residual_excess(member.fit.rms[0], result.fit->rms[j],
                                                     points[member.cluster].size(), bound, 3,
                                                     options.length_tolerance)
                                   : std::numeric_limits<double>::infinity(),
                        j);
    }
    return result;
  };
  std::vector<std::pair<std::vector<std::size_t>, Fit>> fitted;
  for (std::size_t s = 0; s < sets.size(); ++s) {
    Fit joint;
    // The fit of the members left: after a member leaves, the one made while choosing it.
    std::optional<Assessed> all;
    std::vector<std::size_t> left;  // the members that leave: a set of their own, tested in turn
    while (sets[s].size() > 1) {
      if (!all) all = assess(sets[s]);
      if (!(all->excess.largest > 1)) {
        joint = std::move(all->fit);
        break;
      }
      auto [leaving, without_leaving] = member_that_leaves(
          every_member(sets[s].size()), all->excess.worst,
          [&](std::size_t j) {
            const AlignedCylinder& member = cylinders[sets[s][j]];
            return all->fit ? residual_pull(member.fit.rms[0], all->fit->rms[j],
                                            points[member.cluster].size())
                            : std::numeric_limits<double>::quiet_NaN();
          },
          [&](std::size_t j) {
            std::vector<std::size_t> others = sets[s];
            others.erase(others.begin() + static_cast<std::ptrdiff_t>(j));
            return assess(others);
          });
      left.push_back(sets[s][leaving]);
      sets[s].erase(sets[s].begin() + static_cast<std::ptrdiff_t>(leaving));
      all = std::move(without_leaving);
    }
    fitted.emplace_back(sets[s], std::move(joint));
    if (!left.empty()) {
      std::sort(left.begin(), left.end());  // best located first
      sets.push_back(std::move(left));
    }
  }
  return fitted;
}

// The joint fit with `direction` of the cylinders `set` (indices into `cylinders`): one line
// through them, each keeping its own radius, from the information-weighted mean of their own
// lines.
std::optional<CoaxialFit> fit_on_one_line(const Eigen::Vector3d& direction,
                                          const std::vector<AlignedCylinder>& cylinders,
                                          const std::vector<std::size_t>& set,
                                          const std::vector<std::vector<Vec3>>& points,
                                          const std::vector<std::vector<double>>& weights) {
  std::vector<CoaxialMember> members;
  PooledCentre pooled;
  for (const std::size_t k : set) {
    const std::size_t c = cylinders[k].cluster;
    members.push_back({points[c], weights[c], cylinders[k].fit.radii[0]});
    pooled.add(cylinders[k].fit);
  }
  return fit_coaxial(direction, pooled.centre(), members);
}

// A coaxial set fitted on one line of free direction: the set as one item of its direction group,
// and the members' residuals.
struct FreeLineFit {
  Oriented item;
  std::vector<double> rms;  // per member, unweighted, at least kResolution × its radius
};

// The state of fit_free_line(): an axis line of free direction through a coaxial set, each
// member keeping its own radius. Parameters: the tilt along u and v times `scale` (one unit in
// every column), the line's shift along u and v, the radii. The line pivots where the points are
// along it, so that a tilt hardly moves them on average.
class FreeLine {
 public:
  FreeLine(const Eigen::Vector3d& direction, const CoaxialFit& start,
           std::span<const std::size_t> clusters, const std::vector<std::vector<Vec3>>& points,
           const std::vector<std::vector<double>>& weights)
      : clusters_(clusters),
        points_(points),
        weights_(weights),
        members_(static_cast<Eigen::Index>(clusters.size())),
        direction_(direction),
        radii_(start.radii),
        scale_(*std::max_element(radii_.begin(), radii_.end())) {
    std::tie(u_, v_) = orthonormal_pair(direction_);
    pivot_ = start.centre.x() * u_ + start.centre.y() * v_;
    recentre();
  }

  double scale() const { return scale_; }
  const Eigen::Vector3d& direction() const { return direction_; }
  const Eigen::Vector3d& u() const { return u_; }
  const Eigen::Vector3d& v() const { return v_; }
  double radius(std::size_t k) const { return radii_[k]; }

  // Residuals e = |Q(x − pivot)| − r, Q = I − d dᵀ: `visit(k, w, e, line)` gets each point of
  // member k, its weight, its residual and its derivatives: `line` for the line's four
  // parameters, −1 for its radius.
  template <typename Visit>
  void for_each_residual(const Visit& visit) const {
    for (Eigen::Index k = 0; k < members_; ++k) {
      const std::size_t c = clusters_[static_cast<std::size_t>(k)];
      for (std::size_t i = 0; i < points_[c].size(); ++i) {
        const Eigen::Vector3d d = to_eigen(points_[c][i]) - pivot_;
        const double t = direction_.dot(d);
        const Eigen::Vector3d radial = d - t * direction_;
        const double length = radial.norm();
        if (!(length > 0)) continue;
        const Eigen::Vector3d normal = radial / length;
        visit(k, weights_[c][i], length - radii_[static_cast<std::size_t>(k)],
              Eigen::Vector4d(-t / scale_ * normal.dot(u_), -t / scale_ * normal.dot(v_),
                              -normal.dot(u_), -normal.dot(v_)));
      }
    }
  }

  // Adds a residual's Jacobian row, times `weight`, to the (symmetric) normal matrix `matrix`:
  // its upper part only, the lower filled by symmetric().
  static void add_row(Eigen::MatrixXd& matrix, Eigen::Index k, double weight,
                      const Eigen::Vector4d& line) {
    matrix.topLeftCorner<4, 4>() += weight * line * line.transpose();
    matrix.block<4, 1>(0, 4 + k) -= weight * line;
    matrix(4 + k, 4 + k) += weight;
  }
  void symmetric(Eigen::MatrixXd& matrix) const {
    matrix.bottomLeftCorner(members_, 4) = matrix.topRightCorner(4, members_).transpose();
  }

  // Takes a Gauss–Newton step; false when a radius ends non-positive.
  bool move(const Eigen::VectorXd& delta) {
    direction_ = (direction_ + delta(0) / scale_ * u_ + delta(1) / scale_ * v_).normalized();
    pivot_ += delta(2) * u_ + delta(3) * v_;
    for (Eigen::Index k = 0; k < members_; ++k) {
      radii_[static_cast<std::size_t>(k)] += delta(4 + k);
      if (!(radii_[static_cast<std::size_t>(k)] > 0)) return false;
    }
    std::tie(u_, v_) = orthonormal_pair(direction_);
    recentre();
    return true;
  }

 private:
  void recentre() {
    pivot_ += direction_ *
              (middle_along(direction_, clusters_, points_, weights_) - direction_.dot(pivot_));
  }

  std::span<const std::size_t> clusters_;
  const std::vector<std::vector<Vec3>>& points_;
  const std::vector<std::vector<double>>& weights_;
  Eigen::Index members_;
  Eigen::Vector3d direction_, u_, v_, pivot_;
  std::vector<double> radii_;
  double scale_;
};

// A coaxial set's members fitted with one axis line whose direction is free too (Gauss–Newton
// from `direction` and the set's joint fit with it, weighted steps as the joint fits take them),
// as one item of its direction group: its direction, and how well all its points determine it
// together (from the unweighted residuals, as oriented_cylinder()'s). Sharing the line ties the
// members: two short steps of a shaft far apart fix the axis better than each does alone. Nothing
// when the iteration does not settle or a radius ends non-positive.
std::optional<FreeLineFit> fit_free_line(const Eigen::Vector3d& direction, const CoaxialFit& start,
                                         std::span<const std::size_t> clusters,
                                         const std::vector<std::vector<Vec3>>& points,
                                         const std::vector<std::vector<double>>& weights) {
  std::size_t count = 0;
  for (const std::size_t c : clusters) count += points[c].size();
  const Eigen::Index parameters = 4 + static_cast<Eigen::Index>(clusters.size());
  if (count <= static_cast<std::size_t>(parameters)) return std::nullopt;
  FreeLine line(direction, start, clusters, points, weights);
  if (!(line.scale() > 0)) return std::nullopt;
  Eigen::MatrixXd weighted(parameters, parameters);
  Eigen::VectorXd gradient(parameters);
  constexpr int kMaxSteps = 30;
  for (int step = 0;; ++step) {
    weighted.setZero();
    gradient.setZero();
    line.for_each_residual([&](Eigen::Index k, double w, double e, const Eigen::Vector4d& row) {
      FreeLine::add_row(weighted, k, w, row);
      gradient.head<4>() += w * e * row;
      gradient(4 + k) -= w * e;
    });
    line.symmetric(weighted);
    const Eigen::VectorXd delta = -weighted.ldlt().solve(gradient);
    if (!delta.allFinite()) return std::nullopt;
    if (delta.cwiseAbs().maxCoeff() <= 1e-12 * line.scale()) break;
    if (step == kMaxSteps || !line.move(delta)) return std::nullopt;
  }
  // At the solution: the unweighted information and each member's residual sum.
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(parameters, parameters);
  std::vector<double> member_squares(clusters.size(), 0);
  double squares = 0;
  line.for_each_residual([&](Eigen::Index k, double, double e, const Eigen::Vector4d& row) {
    FreeLine::add_row(information, k, 1, row);
    member_squares[static_cast<std::size_t>(k)] += e * e;
  });
  line.symmetric(information);
  for (const double own : member_squares) squares += own;
  const double scale = line.scale();
  const double residual_variance =
      std::max(squares / double(count - static_cast<std::size_t>(parameters)),
               kResolution * kResolution * scale * scale);
  const Eigen::MatrixXd covariance = information.inverse() * residual_variance;
  if (!covariance.allFinite()) return std::nullopt;
  FreeLineFit fit;
  Oriented& item = fit.item;
  item.cluster = clusters[0];
  item.direction = line.direction();
  item.frame.col(0) = line.u();
  item.frame.col(1) = line.v();
  item.covariance = covariance.topLeftCorner<2, 2>() / (scale * scale);
  item.variance = larger_eigenvalue(item.covariance);
  if (!std::isfinite(item.variance) || !(item.variance > 0)) return std::nullopt;
  for (std::size_t k = 0; k < clusters.size(); ++k)
    fit.rms.push_back(std::max(std::sqrt(member_squares[k] / double(points[clusters[k]].size())),
                               kResolution * line.radius(k)));
  return fit;
}

}  // namespace

void align_cylinders(const Eigen::Vector3d& direction, const Eigen::Matrix3d& direction_covariance,
                     std::vector<AlignedCylinder> cylinders, const RegularityOptions& options,
                     std::vector<Primitive>& primitives,
                     const std::vector<std::vector<Vec3>>& points,
                     const std::vector<std::vector<double>>& weights,
                     std::vector<Relation>& relations, SettledSurfaces& settled) {
  const auto sets =
      fit_coaxial_sets(direction, direction_covariance, cylinders, options, points,
                       [&](const std::vector<std::size_t>& set) {
                         return fit_on_one_line(direction, cylinders, set, points, weights);
                       });
  for (const auto& [members, fit] : sets) {
    const CoaxialFit& joint = fit ? *fit : cylinders[members[0]].fit;
    std::size_t coaxial_index = kNoRelation;
    if (members.size() > 1) {
      coaxial_index = relations.size();
      Relation& coaxial = relations.emplace_back();
      coaxial.kind = Relation::Kind::Coaxial;
      for (const std::size_t k : members) coaxial.members.push_back(cylinders[k].cluster);
      std::sort(coaxial.members.begin(), coaxial.members.end());
    }
    const std::size_t line = settled.lines.size();
    std::vector<std::size_t> clusters;
    for (const std::size_t k : members) clusters.push_back(cylinders[k].cluster);
    settled.lines.push_back({direction, joint.centre, joint.centre_covariance, coaxial_index,
                             middle_along(direction, clusters, points, weights),
                             tilt_in_frame(direction, direction_covariance)});
    for (std::size_t j = 0; j < members.size(); ++j) {
      const std::size_t c = clusters[j];
      place_cylinder(primitives[c], direction, joint.centre, joint.radii[j]);
      settled.surfaces.push_back(
          {c, false, line, 0, joint.radii[j], joint.radius_variances[j], joint.rms[j]});
    }
  }
}

bool count_coaxial_as_one(DirectionGroup& group, const std::vector<Oriented>& items,
                          const std::vector<Primitive>& primitives,
                          const std::vector<std::vector<Vec3>>& points,
                          const std::vector<std::vector<double>>& weights,
                          const RegularityOptions& options) {
  const auto is_cylinder = [&](std::size_t i) {
    return primitives[items[i].cluster].type == PrimitiveType::Cylinder;
  };
  if (std::count_if(group.members.begin(), group.members.end(), is_cylinder) < 2) return false;
  std::vector<AlignedCylinder> cylinders;
  for (const std::size_t i : group.members) {
    const std::size_t c = items[i].cluster;
    if (primitives[c].type != PrimitiveType::Cylinder) continue;
    if (std::optional<AlignedCylinder> cylinder =
            aligned_cylinder(c, primitives[c], group.direction, points, weights))
      cylinders.push_back(std::move(*cylinder));
  }
  if (cylinders.size() < 2) return false;
  // The clusters of `set`, in its order.
  const auto clusters_of = [&](const std::vector<std::size_t>& set) {
    std::vector<std::size_t> clusters(set.size());
    for (std::size_t j = 0; j < set.size(); ++j) clusters[j] = cylinders[set[j]].cluster;
    return clusters;
  };
  const auto sets = fit_coaxial_sets(
      group.direction, group.covariance, cylinders, options, points,
      [&](const std::vector<std::size_t>& set) -> std::optional<FreeLineFit> {
        const std::optional<CoaxialFit> start =
            fit_on_one_line(group.direction, cylinders, set, points, weights);
        if (!start) return std::nullopt;
        return fit_free_line(group.direction, *start, clusters_of(set), points, weights);
      });
  bool counted = false;
  for (const auto& [set, fit] : sets) {
    if (!fit) continue;
    std::vector<std::size_t> clusters = clusters_of(set);
    std::sort(clusters.begin(), clusters.end());
    count_as_one(group, items, clusters, fit->item);
    counted = true;
  }
  return counted;
}

}  // namespace primseg::detail
