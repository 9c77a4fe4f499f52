#pragma once
// The stages of regularize() (src/regularity.hpp), one source each in src/regularity/, and what
// they hand one another. In the order regularize() runs them: directions grouped where they agree
// (directions.cpp), each group's coplanar planes (coplanar.cpp) and coaxial cylinders (coaxial.cpp)
// counted as one, right angles made exact; then each group's planes and cylinders refitted with
// its direction, on shared planes and axis lines; spheres centred on the lines and cylinders and
// spheres of one radius (radii.cpp); last, tangencies (tangency.cpp). The joint least-squares fits
// of cylinders and spheres are in joint_fit.cpp, the tests they share in statistics.cpp.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <type_traits>
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

// ---- Tests and tolerances (statistics.cpp)

/// Whether a difference of size `size` is within a tolerance (RegularityOptions::angle_tolerance,
/// length_tolerance), which then passes a test whatever its statistic; never for a tolerance of 0.
bool within_tolerance(double size, double tolerance);

/// A test's score with a tolerance, where candidates rank by their scores: passed at or below
/// `bound`, it also passes when within_tolerance(size, tolerance), and such a difference then
/// ranks by its size against the tolerance. A tolerance of 0 leaves the score as it is.
double tolerated(double score, double bound, double size, double tolerance);

/// The χ² value a sum of `freedom` squared standard normals exceeds as rarely as one normal
/// exceeds `significance` in magnitude: exact for one and two degrees of freedom,
/// Wilson–Hilferty's approximation beyond (within 1.1% of the exact quantile from three on at a
/// significance of 3).
double chi_square_bound(double significance, std::size_t freedom);

/// How far a joint fit explains a member worse than its own fit did: the rise of its residual sum
/// over `bound` (a χ² bound, guard_bound()) times its residual variance (estimated with the
/// degrees of freedom of the member's own fit, of `parameters` parameters), or, when lower, the
/// rise of its mean square against the square of the length tolerance. Above 1, it does not
/// belong.
double residual_excess(double own_rms, double joint_rms, std::size_t count, double bound,
                       int parameters, double length_tolerance);

/// The covariance of a direction's tilt (radians², 3x3) in orthonormal_pair(direction)
/// coordinates.
Eigen::Matrix2d tilt_in_frame(const Eigen::Vector3d& direction, const Eigen::Matrix3d& covariance);

/// The significance at which each of `tests` tests must be passed for all of them to fail together
/// as rarely as one test at `significance` does (Bonferroni: the two-sided normal tail divided by
/// their number).
double family_significance(double significance, std::size_t tests);

/// The `bound` of residual_excess() for each of `tests` members of a joint fit that takes
/// `lost` degrees of freedom from each: the χ² bound of those degrees of freedom at the family
/// significance, so that a true member's residual sum, which rises by about its residual variance
/// times a χ² of `lost` degrees of freedom, is sent away as rarely as the significance promises.
double guard_bound(double significance, std::size_t tests, std::size_t lost);

/// How a joint fit explains its members against their own fits, from each one's
/// residual_excess(): how many fail the guard (above 1), the largest excess (at least 1;
/// infinite without a fit), and which member of those that may leave has the largest (`worst`).
struct GuardExcess {
  std::size_t failing = 0;
  double largest = 1;
  std::size_t worst = 0;
  double worst_excess = -std::numeric_limits<double>::infinity();

  /// Counts `member`'s excess.
  void add(double excess, std::size_t member, bool may_leave = true) {
    if (excess > 1) ++failing;
    largest = std::max(largest, excess);
    if (may_leave && excess > worst_excess) {
      worst_excess = excess;
      worst = member;
    }
  }
  /// A joint fit that failed: every member fails.
  static GuardExcess without_fit() {
    GuardExcess excess;
    excess.failing = std::numeric_limits<std::size_t>::max();
    excess.largest = std::numeric_limits<double>::infinity();
    return excess;
  }
};

/// A member's pull on a joint fit (member_that_leaves()): its point count `count` times the rise
/// of its residual sum, from its own fit's RMS `own_rms` to the joint fit's `joint_rms`.
double residual_pull(double own_rms, double joint_rms, std::size_t count);

/// 0, 1, ..., count − 1: every member of a joint fit, as member_that_leaves() takes them.
std::vector<std::size_t> every_member(std::size_t count);

/// How many members, besides the one of the largest excess, a guard refits a joint fit without, at
/// most, to choose the one that leaves (member_that_leaves()).
inline constexpr std::size_t kLeavingTrials = 8;

/// Of more members that may leave than this, the one of the largest excess leaves
/// (member_that_leaves()).
inline constexpr std::size_t kLeavingSetSize = 16;

/// When a joint fit explains some member worse than the significance allows, which member leaves.
/// Not always the one whose own excess is largest (`worst`): a member fitted poorly moves the
/// shared parameters cheaply and pulls them off the exact members, whose excesses then lead, and
/// the guard sent them back one by one until none was left (three exact concentric spheres and a
/// noisy fourth: no relation at all).
///
/// `without(j)` refits without member j and returns that fit with how it explains the others
/// (its `excess`, a GuardExcess). `worst` is taken out first. When others still fail, so are, in
/// turn, the kLeavingTrials members that pull hardest among those of `candidates` (the members that
/// may leave, increasing) that pull harder than `worst`. A member's pull, `pull(j)`, is its point
/// count times its residual sum's rise: the square of the force n δ with which the unweighted least
/// squares hold a member of stiffness n moved by δ, so a member that displaces the others pulls
/// harder than any of them. One of those leaves instead of `worst` only when its absence leaves
/// fewer members failing (of such, the fewest, then the smallest largest excess, then the first).
/// Not the smallest largest excess alone: where several members fail on their own, taking out any
/// other lowers the largest excess a little and fixes nothing (turbine's 564 surfaces of equal
/// radii lost 368 members instead of 43). Of more than kLeavingSetSize candidates, `worst` leaves:
/// one member of n moves the shared parameters by about 1/n of its own offset, so the cascade is
/// one of few members, while a large set's refits are costly and its failing members many
/// (turbine's lost 104 instead of 43, in 20 s instead of 1.4). Returns the member that leaves and
/// what `without` returned for it.
template <class Pull, class Without>
auto member_that_leaves(const std::vector<std::size_t>& candidates, std::size_t worst,
                        const Pull& pull, const Without& without) {
  using Refitted = std::invoke_result_t<Without, std::size_t>;
  std::pair<std::size_t, Refitted> leaving{worst, without(worst)};
  GuardExcess least = leaving.second.excess;
  if (least.failing == 0 || candidates.size() > kLeavingSetSize) return leaving;
  const double worst_pull = pull(worst);
  std::vector<std::pair<double, std::size_t>> harder;  // (pull, member), pulling harder than worst
  for (const std::size_t j : candidates)
    if (const double p = pull(j); j != worst && p > worst_pull) harder.emplace_back(p, j);
  std::stable_sort(harder.begin(), harder.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  if (harder.size() > kLeavingTrials) harder.resize(kLeavingTrials);
  std::sort(harder.begin(), harder.end(),
            [](const auto& a, const auto& b) { return a.second < b.second; });
  for (const auto& [unused, j] : harder) {
    Refitted refitted = without(j);
    const GuardExcess& excess = refitted.excess;
    if (excess.failing < least.failing ||
        (excess.failing == least.failing && leaving.first != worst &&
         excess.largest < least.largest)) {
      least = excess;
      leaving = {j, std::move(refitted)};
    }
  }
  return leaving;
}

// ---- Directions (directions.cpp)

/// A primitive with a direction (a plane's normal, a cylinder's axis) and how well its inliers
/// determine it.
struct Oriented {
  std::size_t cluster = 0;
  Eigen::Vector3d direction;
  double variance = 0;  // of its tilt, radians², in the worst direction
  // Covariance of the tilt (radians²) along the tangent directions `frame` (columns).
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  Eigen::Matrix<double, 3, 2> frame;
};

/// Directions tested parallel, and their common direction: the minimiser over unit d of
/// Σ δᵢᵀ Cᵢ⁻¹ δᵢ, δᵢ the tilt of d from member i's direction in its frame, which is the smallest
/// eigenvector of Σ Fᵢ Cᵢ⁻¹ Fᵢᵀ (for a plane, its scatter matrix over the residual variance).
struct DirectionGroup {
  Eigen::Vector3d direction;
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< of the direction's tilt (radians²)
  std::vector<std::size_t> members;                      ///< indices into the Oriented items
};

/// The angle between two lines of directions a and b (radians, in [0, π/2]).
double angle_between_lines(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

/// A plane cluster's normal from its unweighted least-squares fit to `points` (its inliers), with
/// its tilt's covariance (σ̂²/λ along each in-plane eigenvector of the scatter); nothing for fewer
/// than 6 points or collinear ones.
std::optional<Oriented> oriented_plane(std::size_t cluster, std::span<const Vec3> points);

/// A cylinder's axis, with its tilt's covariance from the Jacobian of its residuals on `points`
/// (its inliers) at `cylinder`; nothing for fewer than 12 points, a radius that is not positive or
/// a singular fit.
std::optional<Oriented> oriented_cylinder(std::size_t cluster, const Primitive& cylinder,
                                          std::span<const Vec3> points);

/// The group's direction and its covariance, from its information.
void form_direction(DirectionGroup& group);

/// Visited from the best-determined direction, each joins the group it is within the significance
/// (or the angle tolerance) of (the best score), else starts one.
std::vector<DirectionGroup> group_directions(const std::vector<Oriented>& items,
                                             const RegularityOptions& options);

/// `joined` counts as the members of `set` (clusters, increasing) in their group's direction: the
/// sum of the members' information gives way to its. The group's direction is formed again by the
/// caller.
void count_as_one(DirectionGroup& group, const std::vector<Oriented>& items,
                  std::span<const std::size_t> set, const Oriented& joined);

/// Pairs of direction groups at right angles within the significance (or the angle tolerance),
/// made exactly so.
///
/// Pairs are taken by increasing score, each scored again when it comes up on the directions the
/// pairs kept before it left (a kept pair moves its component's directions), so pairs up to twice
/// the significance wait in the queue. The kept pairs join the
/// groups into components. In a component of at most kLargestFrame groups (a part's frames: its
/// directions at right angles) every constraint is met by least squares from the measured
/// directions, each moved along its covariance (sweeps of make_orthogonal), and a pair within a
/// component is tried only when it closes a triangle (two directions orthogonal to a third, made
/// orthogonal to each other); other cycles need not be satisfiable. A larger component is a tree
/// of chance right angles between a freeform surface's many planes (bunny00: 486 pairs among 488
/// groups): a pair joining two of them is met by its own two directions, each side turning
/// rigidly with its own, so it costs O(G), not sweeps over every constraint. Either way the pair
/// is kept only when no direction ends beyond the significance (or the angle tolerance) of its
/// measurement. Returns the kept pairs (indices into `groups`, first < second), in increasing
/// order.
std::vector<std::pair<std::size_t, std::size_t>> orthogonalize(std::vector<DirectionGroup>& groups,
                                                               const RegularityOptions& options);

/// Groups the right angles made one direction. On an exact CAD mesh directions are known to a
/// tiny fraction of a degree, and two groups of faces the part means to be parallel can differ by
/// more than that before the right angles; each then made orthogonal to the same two others, they
/// end with one direction to round-off. They are one group: the first keeps its direction and
/// takes the other's members, information, coplanar sets and right angles (`orthogonal`, indices
/// into `groups`, renumbered; the emptied group keeps none).
void merge_parallel_groups(std::vector<DirectionGroup>& groups,
                           std::vector<std::pair<std::size_t, std::size_t>>& orthogonal,
                           std::vector<std::vector<std::vector<std::size_t>>>& coplanar);

// ---- Joint fits of cylinders and spheres (joint_fit.cpp)

/// One cylinder of a joint fit: its inliers, and the axis line and the radius it takes (indices
/// into the fit's lines and radii).
struct CylinderTerm {
  std::span<const Vec3> points;
  std::span<const double> weights;
  std::size_t line = 0;
  std::size_t radius = 0;
};

/// No line: the `line` of a sphere (a joint fit's term, a settled surface) whose centre is its own.
inline constexpr std::size_t kNoLine = std::numeric_limits<std::size_t>::max();

/// A sphere's points: sphere s of a joint fit has one of its radii and one of its centres, free or
/// on one of its lines (one parameter along it). Spheres of one centre are concentric, and give
/// it the same line (or none).
struct SphereTerm {
  std::span<const Vec3> points;
  std::span<const double> weights;
  std::size_t radius = 0;
  std::size_t line = kNoLine;
  std::size_t centre = 0;
};

/// Axis lines of fixed directions, sphere centres and radii fitted together by geometric least
/// squares: each cylinder term's residuals are its points' distances to its line minus its radius,
/// each sphere's their distances to its centre minus its radius. Several terms on one line are
/// coaxial cylinders (and spheres centred on their axis); several on one radius, cylinders (and
/// spheres) of equal radius.
struct JointFit {
  std::vector<Eigen::Vector2d> centres;  // per line, in orthonormal_pair(direction) coordinates
  std::vector<Eigen::Vector3d> sphere_centres;  // per sphere centre
  std::vector<double> radii;
  // Per cylinder term, then per sphere; unweighted, at least kResolution × the radius.
  std::vector<double> rms;
  // Of (line centres, free sphere centres, the positions along their lines of the centres on
  // one, radii), from the unweighted residuals (if asked).
  Eigen::MatrixXd covariance;
};

/// A cylinder of several on one axis line, each with its own radius: its inliers (input units),
/// their weights, and its radius (a fit's start).
struct CoaxialMember {
  std::span<const Vec3> points;
  std::span<const double> weights;
  double radius = 0;
};

/// Cylinders of fixed direction on one axis line, each with its own radius, fitted together
/// (fit_coaxial()): the line's position, the radii, and how well the fit knows them.
struct CoaxialFit {
  Eigen::Vector2d centre;
  std::vector<double> radii;
  std::vector<double> rms;  // per member, unweighted
  std::vector<double> radius_variances;
  Eigen::Matrix2d centre_covariance = Eigen::Matrix2d::Zero();
};

/// Gauss–Newton from `centres`, `sphere_centres` and `radii` (weighted steps, at most 30; the
/// uncertainty, when asked for, from the unweighted residuals at the solution); a sphere centre on
/// a line starts from its projection onto it. Nothing when it diverges, a radius ends non-positive,
/// the points do not outnumber the parameters, a sphere names no centre of `sphere_centres`, or a
/// centre has no sphere or its spheres put it on different lines. A step of one line and no sphere
/// solves the normal equations whole; otherwise it eliminates each line's and each free centre's
/// position first (a 2x2 or 3x3 block that couples only to its own terms' radii; a centre on a
/// line, its position along it before the line's), so that a plate of n holes of one radius costs
/// O(n), not O(n³).
std::optional<JointFit> fit_cylinders_and_spheres(
    std::span<const Eigen::Vector3d> directions, std::span<const Eigen::Vector2d> centres,
    std::span<const Eigen::Vector3d> sphere_centres, std::span<const double> radii,
    std::span<const CylinderTerm> terms, std::span<const SphereTerm> spheres, bool with_covariance);

/// The cylinders `members` on one line of direction `axis` through `centre`
/// (orthonormal_pair(axis) coordinates), each keeping its own radius: fit_cylinders_and_spheres()
/// with its covariance.
std::optional<CoaxialFit> fit_coaxial(const Eigen::Vector3d& axis, const Eigen::Vector2d& centre,
                                      std::span<const CoaxialMember> members);

/// Spheres sharing one centre, each with its own radius (fit_concentric()).
struct ConcentricFit {
  Eigen::Vector3d centre;
  Eigen::Matrix3d centre_covariance = Eigen::Matrix3d::Zero();
  // Per member: its radius, its variance, its residuals' RMS (unweighted, at least kResolution ×
  // its radius).
  std::vector<double> radii, radius_variances, rms;
};

/// The spheres `members` (their inliers, weights and radii; the CoaxialMember of a sphere) fitted
/// with one centre, each keeping its own radius: fit_cylinders_and_spheres() from `centre` and
/// their radii, with its covariance.
std::optional<ConcentricFit> fit_concentric(const Eigen::Vector3d& centre,
                                            std::span<const CoaxialMember> members);

/// `cylinder` refitted alone on its inliers with the axis direction `direction`, from its own axis
/// point and radius.
std::optional<CoaxialFit> fit_alone(const Primitive& cylinder, const Eigen::Vector3d& direction,
                                    std::span<const Vec3> points, std::span<const double> weights);

/// The weighted mean of direction · x over the points of `clusters`.
double middle_along(const Eigen::Vector3d& direction, std::span<const std::size_t> clusters,
                    const std::vector<std::vector<Vec3>>& points,
                    const std::vector<std::vector<double>>& weights);

/// `cylinder` on the line of `direction` through `centre` (orthonormal_pair(direction)
/// coordinates), its axis on its own side and its point the line's nearest to the old one, so
/// that it stays by the cluster.
void place_cylinder(Primitive& cylinder, const Eigen::Vector3d& direction,
                    const Eigen::Vector2d& centre, double radius);

/// The information-weighted mean of positions of dimension D: where a set's common position is
/// (an axis line's in the plane orthogonal to it, a sphere centre), and how well.
template <int D>
struct PooledPosition {
  using Vector = Eigen::Matrix<double, D, 1>;
  using Matrix = Eigen::Matrix<double, D, D>;
  Matrix information = Matrix::Zero();
  Vector weighted = Vector::Zero();  // Σ information × position

  void add(const Vector& position, const Matrix& covariance) {
    const Matrix own = covariance.inverse();
    information += own;
    weighted += own * position;
  }
  Vector centre() const {
    // One dimension divides: g++ 12 takes Eigen's 1x1 LDLT for an out-of-bounds access.
    if constexpr (D == 1)
      return weighted / information(0, 0);
    else
      return information.ldlt().solve(weighted);
  }
  Matrix covariance() const { return information.inverse(); }
};

/// Where a coaxial set's axis is, and how well.
struct PooledCentre : PooledPosition<2> {
  using PooledPosition<2>::add;
  void add(const CoaxialFit& fit) { add(fit.centre, fit.centre_covariance); }
};

// ---- Spheres on axis lines, and equal radii (radii.cpp)

/// The surfaces with a radius, for the spheres on axes and the equal radii: the cylinders refitted
/// so far, each on an axis line (coaxial ones on a shared one), and the spheres, each on its
/// centre (on a line, once centred on one).
struct SettledSurfaces {
  struct Line {
    Eigen::Vector3d direction;
    Eigen::Vector2d centre;  // orthonormal_pair(direction) coordinates
    // Of `centre`, the direction fixed: how well the line is placed where its points are.
    Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
    std::size_t coaxial = kNoRelation;  // its coaxial relation's index
    // Where its cylinders' points are along it (their weighted mean of direction · x), and the
    // covariance of the direction's tilt (radians², orthonormal_pair(direction) coordinates):
    // at a distance h from there the line is placed to within covariance + h² tilt.
    double middle = 0;
    Eigen::Matrix2d tilt = Eigen::Matrix2d::Zero();
  };
  struct Surface {
    std::size_t cluster = 0;
    bool sphere = false;
    std::size_t line = 0;    // into `lines`: a cylinder's; a sphere's centre's, or kNoLine
    std::size_t centre = 0;  // a sphere's, into `centres` (one for a concentric set's)
    double radius = 0, radius_variance = 0, rms = 0;
  };
  std::vector<Line> lines;
  std::vector<Eigen::Vector3d> centres;
  std::vector<Eigen::Matrix3d> centre_covariances;  // of each sphere's own fit
  std::vector<Surface> surfaces;
};

/// Spheres centred on an axis line: a ball end, a hemispherical cap, a spherical seat of a hole.
/// Each sphere whose centre is within the significance of a line (Mahalanobis, over the offset in
/// the line's plane, with the covariances of the centre, of the line's position and of its tilt
/// times the centre's distance along it from the line's points, against the χ² bound of two
/// degrees of freedom) and within
/// max_radius_difference of its radius joins the nearest such line. As for the radii, an offset
/// whose significance interval is wider than that joins none: the centres of sphere patches of a
/// freeform surface are known to a few percent of their radii, and any line would do (bunny00's
/// level of 391 clusters had 22 such pairs without this rule, none with it; CAD parts' centres are
/// known to 1e-6 of their radii, fandisk's to 5e-4). Nor does a line known less well than its
/// cylinders' radius (a nearly flat cylinder's axis could be anywhere). Each line's cylinders and
/// spheres are then refitted together, every sphere with one parameter along the line instead of
/// three; as for a coaxial set, while a member's residual sum rises by more than the significance
/// corrected for the number of members allows, a sphere leaves (member_that_leaves()). Appends each
/// joined sphere to its line's coaxial relation, which it starts when the line had one cylinder.
void centre_spheres_on_axes(SettledSurfaces& settled, const RegularityOptions& options,
                            std::vector<Primitive>& primitives,
                            const std::vector<std::vector<Vec3>>& points,
                            const std::vector<std::vector<double>>& weights,
                            std::vector<Relation>& relations);

/// Spheres centred on one line of a design direction with no cylinder on it: the arcs of a
/// revolved profile (couplingdown has seven spheres centred on one line along z). For each
/// direction a relation made exact (refitted[g] not empty), in order, the spheres on no line yet,
/// best located first, each join the first set whose pooled position in the plane orthogonal to
/// the direction they are within the significance of (the χ² bound of two degrees of freedom, with
/// the covariances of the centre, of the pooled position and of the direction's tilt times the
/// height between them) and within max_radius_difference of their radius; a centre known less well
/// than that joins none. A set of kFewestSpheresOnALine or more, at as many places along the
/// direction (spheres of one place are concentric instead), becomes a line of its own, refitted
/// with its spheres (settle_on_line, as many staying), and a coaxial relation of them.
void line_up_spheres(SettledSurfaces& settled, const std::vector<DirectionGroup>& groups,
                     const std::vector<std::vector<std::size_t>>& refitted,
                     const RegularityOptions& options, std::vector<Primitive>& primitives,
                     const std::vector<std::vector<Vec3>>& points,
                     const std::vector<std::vector<double>>& weights,
                     std::vector<Relation>& relations);

/// Spheres sharing one centre, each with its own radius: a ball and its socket, a spherical
/// shell's two sides. Among the spheres on no line, best located first, each joins the first set
/// whose pooled centre (information-weighted) it is within the significance of (Mahalanobis, with
/// both covariances, against the χ² bound of three degrees of freedom) and within
/// max_radius_difference of its radius; else it starts one. As for a line's spheres, a centre whose
/// significance interval is wider than that joins none (the spheres of a freeform surface). Each
/// set of two or more is refitted with one centre (fit_concentric()); while a member's residual
/// sum rises by more than the significance corrected for their number allows, a member leaves
/// (member_that_leaves()).
/// Then on each line, its spheres whose places along it agree (places_along) are refitted
/// with the line, one place per set, with the same guard. Appends a Concentric relation per set
/// kept, and gives its members one centre in `settled`: equalize_radii() keeps it shared
/// (fragments of one sphere, whose radii agree, are made one there).
void make_concentric(SettledSurfaces& settled, const RegularityOptions& options,
                     std::vector<Primitive>& primitives,
                     const std::vector<std::vector<Vec3>>& points,
                     const std::vector<std::vector<double>>& weights,
                     std::vector<Relation>& relations);

/// Cylinders and spheres of equal radius within the significance (radius_classes) share one
/// radius: each component of surfaces joined by a class, by an axis line (a coaxial set) or by a
/// sphere centre (a concentric set) is refitted by one joint least squares over its lines'
/// positions, its spheres' centres and its radii, the directions kept. As for a coaxial set, a
/// member leaves its class while the joint fit explains one worse than its own by more than the
/// significance (member_that_leaves()). Appends the classes of two or more to `relations`.
void equalize_radii(const SettledSurfaces& settled, const RegularityOptions& options,
                    std::vector<Primitive>& primitives,
                    const std::vector<std::vector<Vec3>>& points,
                    const std::vector<std::vector<double>>& weights,
                    std::vector<Relation>& relations);

// ---- Axis lines (coaxial.cpp)

/// A cylinder of a direction group, refitted alone with the group's direction.
struct AlignedCylinder {
  std::size_t cluster = 0;
  CoaxialFit fit;
  double middle = 0;  // where its inliers are along the direction: middle_along()
};

/// Cylinder `c` refitted alone with `direction` (fit_alone()), and where it is along it.
std::optional<AlignedCylinder> aligned_cylinder(std::size_t c, const Primitive& cylinder,
                                                const Eigen::Vector3d& direction,
                                                const std::vector<std::vector<Vec3>>& points,
                                                const std::vector<std::vector<double>>& weights);

/// Refits the cylinders of a direction group: each coaxial set around one axis line (each member
/// keeping its own radius), the others alone with the group's direction. Appends the coaxial sets
/// of two or more to `relations`, and every cylinder refitted to `settled`.
void align_cylinders(const Eigen::Vector3d& direction, const Eigen::Matrix3d& direction_covariance,
                     std::vector<AlignedCylinder> cylinders, const RegularityOptions& options,
                     std::vector<Primitive>& primitives,
                     const std::vector<std::vector<Vec3>>& points,
                     const std::vector<std::vector<double>>& weights,
                     std::vector<Relation>& relations, SettledSurfaces& settled);

/// Each coaxial set of a group's cylinders counts as one item: its members fitted on one line of
/// free direction. The sets are align_cylinders()'s, except that the joint fit a set must pass is
/// this one: the group's direction, still to be settled, need not suit all members at once (two
/// steps of a shaft far apart tell the axis better together than the group's direction gives it).
/// Returns whether any set counted.
bool count_coaxial_as_one(DirectionGroup& group, const std::vector<Oriented>& items,
                          const std::vector<Primitive>& primitives,
                          const std::vector<std::vector<Vec3>>& points,
                          const std::vector<std::vector<double>>& weights,
                          const RegularityOptions& options);

// ---- Planes (coplanar.cpp)

/// A plane aligned with a group's direction, by where it is along it.
struct AlignedPlane {
  std::size_t cluster = 0;
  Eigen::Vector3d centroid;  // its inliers' weighted centroid: the aligned plane's point
  double offset = 0;         // direction · centroid
  double variance = 0;       // the offset's
  double weight = 0;         // Σ w
};

/// The plane with normal ±`direction` (its own side) through its inliers' weighted centroid;
/// false (the plane unchanged) when they weigh nothing.
bool align_plane(Primitive& plane, const Eigen::Vector3d& direction, std::span<const Vec3> points,
                 std::span<const double> weights);

/// Its offset along `direction` (that of its inliers' weighted centroid, where align_plane()
/// puts it), and how well it is known: the weighted mean of the inliers' offsets has variance
/// σ̂² Σw² / (Σw)², σ̂² their weighted mean square about it with the plane's 3 degrees of freedom
/// taken (floored at the resolution of its extent, as its direction's is).
std::optional<AlignedPlane> aligned_plane(std::size_t cluster, const Eigen::Vector3d& direction,
                                          std::span<const Vec3> points,
                                          std::span<const double> weights);

/// The planes of `set` (aligned with `direction` through their inliers' weighted centroids) made
/// one plane through all their inliers, each keeping its side: the least-squares offset with the
/// direction fixed is the weighted mean of theirs. Appends the Coplanar relation.
void share_one_plane(const Eigen::Vector3d& direction, const std::vector<std::size_t>& set,
                     std::vector<Primitive>& primitives,
                     const std::vector<std::vector<double>>& weights,
                     std::vector<Relation>& relations);

/// Sets of a direction group's planes (aligned with its direction, of covariance
/// `direction_covariance`) that are one plane within the significance: the fragments
/// of one face that a hole, a boss or the hierarchy cut apart. Best-located first, each joins the
/// first set whose pooled offset it is within the significance of, counting both offsets'
/// variances and the direction's tilt over the distance between its centroid and the set's first
/// member's; else it starts one. A set must then be explained by one plane of the direction
/// through all its inliers as each member was by its own: the guard of the coaxial sets (the
/// significance corrected for the number of members), a member leaving while it fails
/// (member_that_leaves()); those that leave a set are a set of their own, tested in turn. Returns
/// the sets of two or more, as clusters, increasing.
std::vector<std::vector<std::size_t>> coplanar_sets(const Eigen::Matrix3d& direction_covariance,
                                                    std::vector<AlignedPlane> planes,
                                                    const RegularityOptions& options);

/// Each coplanar set of a group counts as one plane: the union's scatter (about the union's
/// centroid) also holds how far apart the fragments lie, so the direction is known better than
/// from the members' own scatters. Returns whether any did.
bool count_coplanar_as_one(DirectionGroup& group, const std::vector<Oriented>& items,
                           const std::vector<std::vector<std::size_t>>& sets,
                           const std::vector<std::vector<Vec3>>& points);

// ---- Tangencies (tangency.cpp)

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

/// Member i of a line tangent to a held cylinder of the same direction, whose axis is at `centre`
/// (orthonormal_pair(direction) coordinates) and whose radius is R: |c − centre| = partner_sign · R
/// + own_sign · rᵢ. (+1, +1): each outside the other (a fillet around a boss); (+1, −1): inside the
/// held one (a fillet in a bore); (−1, +1): around it.
struct CircleHold {
  Eigen::Vector2d centre;
  double radius = 0, partner_sign = 1, own_sign = 1;
  Eigen::Index member = 2;  ///< rᵢ's index in y
};

/// A condition on cylinders of fixed direction on one axis line, on y = (c, r₀, r₁, …): the line's
/// position c in orthonormal_pair(direction) coordinates and each member's radius. Linear ones are
/// row · y = target. Member i tangent to a plane of unit normal n (orthogonal to the axis; (n·u,
/// n·v) in those coordinates) and offset n · x = o, with the axis on `side` (±1) of it: row = (n·u,
/// n·v, 0, …, −side at rᵢ, …), target = o. Member i of a given radius (shared with others of equal
/// radius off the line): row = e(rᵢ), target = r. Members i and j of one radius: row = e(rᵢ) −
/// e(rⱼ), target = 0. Member i tangent to a parallel cylinder: `circle`, and `row` and `target` its
/// linearisation at the y it was tested at (linearised()).
struct LineHold {
  Eigen::VectorXd row;
  double target = 0;
  std::optional<CircleHold> circle;
};

/// fit_held_line()'s result.
struct HeldLineFit {
  Eigen::VectorXd y;  ///< (c, r₀, r₁, …), as LineHold's
  double rms = 0;     ///< unweighted, over every member's points, at least kResolution × a radius
  std::size_t free = 0;        ///< the parameters − the number of holds
  std::size_t count = 0;       ///< points
  Eigen::MatrixXd covariance;  ///< of y, from the unweighted residuals; rank `free`
};

/// The cylinders `members` of axis direction `direction`, on one line, fitted to their points by
/// geometric least squares (weighted residuals |Q(x − c)| − rᵢ) subject to `holds` (at most as
/// many as the parameters, 2 + the members): Gauss–Newton over the free coordinates z of y = y₀ +
/// N z, y₀ the start (`centre` and the members' radii) projected onto the holds and N an
/// orthonormal basis of their rows' null space. A circle's hold is linearised again at every step,
/// y projected onto it again and N formed again (a Newton step on the condition, then one of
/// Gauss–Newton along it: a fixed point meets the condition and is stationary along it). Nothing
/// when the holds are (nearly) dependent (one plane twice, parallel planes on one side of the
/// axis), the iteration does not converge in 50 steps, a radius ends non-positive or the points do
/// not outnumber the free parameters.
std::optional<HeldLineFit> fit_held_line(const Eigen::Vector3d& direction,
                                         const Eigen::Vector2d& centre,
                                         std::span<const CoaxialMember> members,
                                         std::span<const LineHold> holds);

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
