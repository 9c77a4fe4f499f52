// The tangency stage of regularize(): cylinders held tangent to the planes and the parallel
// cylinders they border (make_tangent(), whose rules are at its definition).
#include "regularity/stages.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include "eigen_conversions.hpp"
#include "orthonormal_pair.hpp"

namespace primseg::detail {

double distance_across(const Eigen::Vector3d& apart, const Eigen::Vector3d& direction) {
  return (apart - apart.dot(direction) * direction).norm();
}

CircleContact nearest_circle_contact(double distance, double radius, double held) {
  CircleContact nearest{1, 1, distance - (held + radius)};
  for (const auto& [partner_sign, own_sign] : {std::pair{1.0, -1.0}, {-1.0, 1.0}}) {
    const double target = partner_sign * held + own_sign * radius;
    if (target > 0 && std::abs(distance - target) < std::abs(nearest.gap))
      nearest = {partner_sign, own_sign, distance - target};
  }
  return nearest;
}

namespace {

// `hold` as a linear condition at y: itself, or a circle's tangent plane there (row · y − target
// is the circle's own excess |c − centre| − partner_sign · R − own_sign · rᵢ at y).
LineHold linearised(const LineHold& hold, const Eigen::VectorXd& y) {
  if (!hold.circle) return hold;
  const CircleHold& circle = *hold.circle;
  const Eigen::Vector2d apart = y.head<2>() - circle.centre;
  const double distance = apart.norm();
  LineHold linear{Eigen::VectorXd::Zero(y.size()), 0, circle};
  linear.row.head<2>() = apart / distance;
  linear.row(circle.member) = -circle.own_sign;
  const double excess =
      distance - circle.partner_sign * circle.radius - circle.own_sign * y(circle.member);
  linear.target = linear.row.dot(y) - excess;
  return linear;
}

// Round-off of a condition its holds imply, relative to the row or the radius.
constexpr double kImplied = 1e-9;

// Whether `row` is a combination of the holds' rows (linearised at y), to round-off.
bool implied_by(std::span<const LineHold> holds, const Eigen::VectorXd& row,
                const Eigen::VectorXd& y) {
  if (holds.empty()) return false;
  Eigen::MatrixXd rows(row.size(), static_cast<Eigen::Index>(holds.size()));
  for (std::size_t i = 0; i < holds.size(); ++i)
    rows.col(static_cast<Eigen::Index>(i)) = linearised(holds[i], y).row;
  const Eigen::VectorXd combination = rows.colPivHouseholderQr().solve(row);
  return (rows * combination - row).norm() <= kImplied * row.norm();
}

// Whether a point of `points` is also one of `sorted` (sorted): whether two clusters border each
// other (a vertex on their border is an inlier of both).
bool share_a_point(std::span<const Vec3> points, std::span<const Vec3> sorted) {
  return std::any_of(points.begin(), points.end(), [&](const Vec3& p) {
    return std::binary_search(sorted.begin(), sorted.end(), p);
  });
}

// The surfaces a cylinder may be held tangent to.
struct TangentCandidate {
  std::size_t group = 0;              // its direction group
  std::vector<std::size_t> planes;    // of the groups made orthogonal to its own
  std::vector<std::size_t> partners;  // cylinders of its own group, with more points, to hold
};

// A contact line of a cylinder and a plane or a held cylinder it borders: across the axis along
// the plane (direction × normal; for a cylinder, the normal at the contact: along the line
// joining the axes), where the axis is, the sign of the cylinder's side, and the half-width of
// the band about it where the two surfaces are within the noise of each other. A held
// cylinder's contact also has the signs of its CircleHold.
struct Contact {
  std::size_t cylinder = 0, other = 0;  // other: the plane or the held cylinder
  Eigen::Vector3d across;
  double at = 0, side = 1, band = 0;
  double partner_sign = 0, own_sign = 0;  // 0 for a plane
  bool with_plane() const { return own_sign == 0; }
};

// Where x is across a contact line: above 0 on the cylinder's side, below on the other's.
double across_contact(const Contact& contact, const Vec3& x) {
  return (contact.across.dot(to_eigen(x)) - contact.at) * contact.side;
}

// A line to hold tangent: the candidate that found it and its cylinders (that one alone, or the
// members of its Coaxial relation).
struct TangentLine {
  std::size_t first = 0;
  std::vector<std::size_t> cylinders;
};

// The points of a line's cylinders on their own sides of their contacts, as fit_held_line()'s
// members (which view `points` and `weights`: moved, never copied).
struct OwnSides {
  std::vector<std::vector<Vec3>> points;
  std::vector<std::vector<double>> weights;
  std::vector<CoaxialMember> members;

  explicit OwnSides(std::size_t count) : points(count), weights(count) {}
  OwnSides(const OwnSides&) = delete;
  OwnSides& operator=(const OwnSides&) = delete;
  OwnSides(OwnSides&&) = default;
  OwnSides& operator=(OwnSides&&) = default;
  ~OwnSides() = default;
};

// The holds a line's radii start with, and `tied[m]`: the first member of m's class of equal
// radii on the line, m itself for a radius of its own, kNoRelation for a held one.
struct RadiusHolds {
  std::vector<LineHold> holds;
  std::vector<std::size_t> tied;
};

// A tangency that passed its test, ranked by `score`: `contact`, of member `member` of the line (an
// index into its cylinders) against a plane or a held cylinder, as `hold`.
struct TestedContact {
  double score = 0;
  const Contact* contact = nullptr;
  std::size_t member = 0;
  LineHold hold;
};

// x in the frame (u, v) of the plane orthogonal to a line's direction.
Eigen::Vector2d in_frame(const std::pair<Eigen::Vector3d, Eigen::Vector3d>& frame,
                         const Eigen::Vector3d& x) {
  return {frame.first.dot(x), frame.second.dot(x)};
}

// y's unit vector e(i), of y's `size`.
Eigen::VectorXd unit(Eigen::Index size, Eigen::Index i) {
  return Eigen::VectorXd::Unit(size, i);
}

// The radius of member m in y = (c, r₀, r₁, …).
Eigen::Index radius_index(std::size_t m) {
  return 2 + static_cast<Eigen::Index>(m);
}

// Whether every radius of `held` is within `fraction` of `own`'s, relative to the larger. A small
// arc held tangent to a plane can flatten into it, its radius running off to 1e15 while its
// residuals stay within the noise (fandisk_large at a significance of 3.44), and the relation is
// then no design intent but a plane given as a cylinder whose distances lose every digit.
bool radii_within(const HeldLineFit& own, const HeldLineFit& held, double fraction) {
  for (Eigen::Index r = radius_index(0); r < own.y.size(); ++r) {
    const double before = own.y(r), after = held.y(r);
    if (!(std::abs(after - before) <= fraction * std::max(before, after))) return false;
  }
  return true;
}

// make_tangent()'s stages, in the order it calls them, over the state they hand on.
class Tangency {
 public:
  Tangency(const std::vector<DirectionGroup>& groups, const RegularityOptions& options,
           std::vector<Primitive>& primitives, const std::vector<std::vector<Vec3>>& points,
           const std::vector<std::vector<double>>& weights, const std::vector<Relation>& relations);

  // The candidate cylinders: those of a group made orthogonal to a plane's, with that group's
  // planes, and those that border a cylinder of their group on another line, about R ± r away.
  void find_candidates(const std::vector<std::pair<std::size_t, std::size_t>>& orthogonal,
                       const std::vector<std::vector<std::size_t>>& refitted);
  // Each candidate's contact lines with the surfaces it borders, and their bands.
  void find_contacts();
  // Each bordered plane's offset from its points beyond every candidate cylinder's band, and its
  // variance.
  void fit_plane_offsets();
  // The lines to hold, in the order they are processed.
  std::vector<TangentLine> lines_in_order();
  // Holds `line` tangent to the surfaces its test keeps, writes its cylinders back and appends
  // the pairs to `tangents`.
  void hold_tangent(const TangentLine& line, std::vector<Relation>& tangents);
  // The planes a cylinder was held tangent to, moved to their refitted offsets.
  void write_plane_offsets();

 private:
  const std::vector<Vec3>& sorted_points(std::size_t c);
  OwnSides own_sides(const std::vector<std::size_t>& cylinders,
                     std::span<const Contact* const> bordered) const;
  RadiusHolds radius_holds(const std::vector<std::size_t>& cylinders) const;
  std::vector<TestedContact> tested_contacts(const TangentLine& line,
                                             std::span<const Contact* const> bordered,
                                             const HeldLineFit& own);

  const std::vector<DirectionGroup>& groups_;
  const RegularityOptions& options_;
  std::vector<Primitive>& primitives_;
  const std::vector<std::vector<Vec3>>& points_;
  const std::vector<std::vector<double>>& weights_;
  const std::vector<Relation>& relations_;
  // Each cluster's Coaxial and EqualRadius relation (kNoRelation for none), and whether it is in
  // a Coplanar one.
  std::vector<std::size_t> line_of_, radius_of_;
  std::vector<bool> shares_offset_;
  std::map<std::size_t, TangentCandidate> candidates_;
  std::map<std::size_t, std::vector<Vec3>> sorted_points_;  // of candidate planes and partners
  std::vector<Contact> contacts_;
  // Each bordered plane's offset, its variance and the centroid it is known best at
  // (aligned_plane()'s, of the points it is fitted from: for a plane of a coplanar set, which keeps
  // the set's offset, its own points, whose offset is known less well than the set's).
  struct HeldOffset {
    double offset = 0, variance = 0;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  };
  std::map<std::size_t, HeldOffset> offsets_;
  std::map<std::size_t, std::size_t> plane_group_;  // each candidate plane's direction group
  std::vector<bool> on_a_line_, settled_, moved_;
  std::map<std::size_t, std::optional<HeldLineFit>> partner_fits_;  // fitted once, alone
};

Tangency::Tangency(const std::vector<DirectionGroup>& groups, const RegularityOptions& options,
                   std::vector<Primitive>& primitives, const std::vector<std::vector<Vec3>>& points,
                   const std::vector<std::vector<double>>& weights,
                   const std::vector<Relation>& relations)
    : groups_(groups),
      options_(options),
      primitives_(primitives),
      points_(points),
      weights_(weights),
      relations_(relations),
      line_of_(primitives.size(), kNoRelation),
      radius_of_(primitives.size(), kNoRelation),
      shares_offset_(primitives.size(), false),
      on_a_line_(primitives.size(), false),
      settled_(primitives.size(), false),
      moved_(primitives.size(), false) {
  for (std::size_t r = 0; r < relations.size(); ++r)
    for (const std::size_t c : relations[r].members) {
      if (relations[r].kind == Relation::Kind::Coaxial) line_of_[c] = r;
      if (relations[r].kind == Relation::Kind::EqualRadius) radius_of_[c] = r;
      if (relations[r].kind == Relation::Kind::Coplanar) shares_offset_[c] = true;
    }
}

const std::vector<Vec3>& Tangency::sorted_points(std::size_t c) {
  std::vector<Vec3>& list = sorted_points_[c];
  if (list.empty()) {
    list = points_[c];
    std::sort(list.begin(), list.end());
  }
  return list;
}

void Tangency::find_candidates(const std::vector<std::pair<std::size_t, std::size_t>>& orthogonal,
                               const std::vector<std::vector<std::size_t>>& refitted) {
  const auto is = [&](std::size_t c, PrimitiveType type) { return primitives_[c].type == type; };
  const auto pair_up = [&](std::size_t cylinder_group, std::size_t plane_group) {
    for (const std::size_t c : refitted[cylinder_group]) {
      if (!is(c, PrimitiveType::Cylinder)) continue;
      TangentCandidate& candidate = candidates_[c];
      candidate.group = cylinder_group;
      for (const std::size_t p : refitted[plane_group])
        if (is(p, PrimitiveType::Plane)) {
          candidate.planes.push_back(p);
          plane_group_[p] = plane_group;
        }
    }
  };
  for (const auto& [i, j] : orthogonal) {
    pair_up(i, j);
    pair_up(j, i);
  }
  // Of two cylinders of one group on different lines, the one of fewer points (a fillet) may be
  // held tangent to the other, which is held as it is. Its axis must be about the sum or the
  // difference of their radii from the other's (within max_radius_difference of its radius)
  // before their points are compared.
  for (std::size_t g = 0; g < groups_.size(); ++g)
    for (const std::size_t a : refitted[g])
      for (const std::size_t b : refitted[g]) {
        if (!is(a, PrimitiveType::Cylinder) || !is(b, PrimitiveType::Cylinder) || a == b ||
            (line_of_[a] != kNoRelation && line_of_[a] == line_of_[b]) ||
            std::pair(points_[a].size(), b) > std::pair(points_[b].size(), a))
          continue;
        const double distance = distance_across(
            to_eigen(primitives_[a].point) - to_eigen(primitives_[b].point), groups_[g].direction);
        const double r = primitives_[a].radius;
        if (!(std::abs(nearest_circle_contact(distance, r, primitives_[b].radius).gap) <=
              options_.max_radius_difference * r) ||
            !share_a_point(points_[a], sorted_points(b)))
          continue;
        TangentCandidate& candidate = candidates_[a];
        candidate.partners.push_back(b);
        candidate.group = g;
      }
}

void Tangency::find_contacts() {
  for (const auto& [key, candidate] : candidates_) {
    const std::size_t c = key;  // not the binding: clang 14 refuses it in a lambda
    // No plane twice: each is in one direction group, and each pair of groups is one right angle.
    const Eigen::Vector3d& direction = groups_[candidate.group].direction;
    // At a distance t along the plane from the contact line the cylinder is t²/2r from it: the
    // surfaces are within the cylinder's residual deviation σ of each other for t < √(2 r σ).
    const Primitive& cylinder = primitives_[c];
    double squares = 0;
    for (const Vec3& x : points_[c]) squares += std::pow(cylinder.distance(x), 2);
    const double deviation = std::max(std::sqrt(squares / static_cast<double>(points_[c].size())),
                                      kResolution * cylinder.radius);
    const auto add_contact = [&](Contact contact) {
      contact.at = contact.across.dot(to_eigen(cylinder.point));
      double side = 0;
      for (std::size_t i = 0; i < points_[c].size(); ++i)
        side += weights_[c][i] * (contact.across.dot(to_eigen(points_[c][i])) - contact.at);
      contact.side = side < 0 ? -1 : 1;
      contacts_.push_back(contact);
    };
    for (const std::size_t p : candidate.planes) {
      if (!share_a_point(points_[c], sorted_points(p))) continue;
      Contact contact{c, p, direction.cross(to_eigen(primitives_[p].axis)).normalized()};
      contact.band = std::sqrt(2 * cylinder.radius * deviation);
      add_contact(contact);
    }
    for (const std::size_t p : candidate.partners) {
      // The condition nearest to the fits as they are; two circles of curvatures 1/r and ±1/R
      // part by t²/2 |1/r ± 1/R| at t from their contact, so the band is √(2σ / |1/r ± 1/R|).
      // Circles of nearly one curvature, one inside the other, stay within the noise of each
      // other too far from their contact to tell a tangency: none below a quarter of 1/r.
      const Eigen::Vector3d apart = to_eigen(cylinder.point) - to_eigen(primitives_[p].point);
      const double distance = distance_across(apart, direction), big = primitives_[p].radius;
      Contact contact{c, p, direction.cross(apart).normalized()};
      const CircleContact nearest = nearest_circle_contact(distance, cylinder.radius, big);
      contact.partner_sign = nearest.partner_sign;
      contact.own_sign = nearest.own_sign;
      const double curvature =
          std::abs(1 / cylinder.radius + contact.partner_sign * contact.own_sign / big);
      if (!(curvature * cylinder.radius >= 0.25) || !(distance > 0)) continue;
      contact.band = std::sqrt(2 * deviation / curvature);
      add_contact(contact);
    }
  }
}

void Tangency::fit_plane_offsets() {
  std::map<std::size_t, std::vector<const Contact*>> contacts_of_plane;
  for (const Contact& contact : contacts_)
    if (contact.with_plane()) contacts_of_plane[contact.other].push_back(&contact);
  std::vector<Vec3> kept;
  std::vector<double> kept_weights;
  for (const auto& [p, bordering] : contacts_of_plane) {
    const Eigen::Vector3d normal = to_eigen(primitives_[p].axis);
    HeldOffset& held = offsets_[p];
    held.offset = normal.dot(to_eigen(primitives_[p].point));
    held.centroid = to_eigen(primitives_[p].point);  // its inliers' centroid (align_plane)
    kept.clear();
    kept_weights.clear();
    double total = 0, sum = 0;
    for (std::size_t i = 0; i < points_[p].size(); ++i) {
      const Vec3& x = points_[p][i];  // not the binding p: clang 14 refuses it in a lambda
      if (!shares_offset_[p] &&
          std::any_of(bordering.begin(), bordering.end(), [&](const Contact* contact) {
            return across_contact(*contact, x) > -contact->band;
          }))
        continue;
      kept.push_back(x);
      kept_weights.push_back(weights_[p][i]);
      total += weights_[p][i];
      sum += weights_[p][i] * normal.dot(to_eigen(x));
    }
    if (!shares_offset_[p] && total > 0) held.offset = sum / total;
    if (const std::optional<AlignedPlane> plane = aligned_plane(p, normal, kept, kept_weights)) {
      held.variance = plane->variance;
      held.centroid = plane->centroid;
    }
  }
}

std::vector<TangentLine> Tangency::lines_in_order() {
  // A line with spheres centred on it is left as it is (a sphere is no candidate): moving the
  // line would move them, and a joint held fit of spheres on a line is not modelled.
  std::vector<TangentLine> lines;
  std::vector<bool> done(primitives_.size(), false);
  for (const auto& [first, candidate] : candidates_) {
    if (done[first]) continue;
    std::vector<std::size_t> cylinders = line_of_[first] == kNoRelation
                                             ? std::vector<std::size_t>{first}
                                             : relations_[line_of_[first]].members;
    for (const std::size_t c : cylinders) done[c] = true;
    if (std::all_of(cylinders.begin(), cylinders.end(),
                    [&](std::size_t c) { return candidates_.contains(c); })) {
      for (const std::size_t c : cylinders) on_a_line_[c] = true;
      lines.push_back({first, std::move(cylinders)});
    }
  }
  // A line tangent to a held cylinder must come after that cylinder's own line, which may move
  // it: lines with partners go last, the largest first (by their largest member's points); a
  // partner whose line comes later is not held.
  const auto has_partner = [&](const TangentLine& line) {
    return std::any_of(line.cylinders.begin(), line.cylinders.end(),
                       [&](std::size_t c) { return !candidates_.at(c).partners.empty(); });
  };
  const auto largest = [&](const TangentLine& line) {
    std::pair<std::size_t, std::size_t> key{0, 0};  // (points, the lowest cluster first)
    for (const std::size_t c : line.cylinders) key = std::max(key, {points_[c].size(), ~c});
    return key;
  };
  const auto first_held = std::stable_partition(
      lines.begin(), lines.end(), [&](const TangentLine& line) { return !has_partner(line); });
  std::stable_sort(first_held, lines.end(), [&](const TangentLine& a, const TangentLine& b) {
    return largest(a) > largest(b);
  });
  return lines;
}

OwnSides Tangency::own_sides(const std::vector<std::size_t>& cylinders,
                             std::span<const Contact* const> bordered) const {
  OwnSides sides(cylinders.size());
  for (std::size_t m = 0; m < cylinders.size(); ++m) {
    const std::size_t c = cylinders[m];
    for (std::size_t i = 0; i < points_[c].size(); ++i)
      if (std::none_of(bordered.begin(), bordered.end(), [&](const Contact* contact) {
            return contact->cylinder == c &&
                   across_contact(*contact, points_[c][i]) < contact->band;
          })) {
        sides.points[m].push_back(points_[c][i]);
        sides.weights[m].push_back(weights_[c][i]);
      }
    sides.members.push_back({sides.points[m], sides.weights[m], primitives_[c].radius});
  }
  return sides;
}

RadiusHolds Tangency::radius_holds(const std::vector<std::size_t>& cylinders) const {
  // A radius shared with clusters off the line is held; one shared only by cylinders on the line
  // (fragments of one fillet) is one parameter of the fit: holding it at the value fitted to the
  // same points would make the tests overconfident.
  const std::size_t count = cylinders.size();
  const Eigen::Index size = radius_index(count);
  RadiusHolds radii{{}, std::vector<std::size_t>(count)};
  for (std::size_t m = 0; m < count; ++m) {
    radii.tied[m] = m;
    std::size_t& tied = radii.tied[m];
    const std::size_t shared_by = radius_of_[cylinders[m]];
    if (shared_by == kNoRelation) continue;
    const std::vector<std::size_t>& shared = relations_[shared_by].members;
    if (std::any_of(shared.begin(), shared.end(), [&](std::size_t c) {
          return std::find(cylinders.begin(), cylinders.end(), c) == cylinders.end();
        })) {
      tied = kNoRelation;
      radii.holds.push_back(
          {unit(size, radius_index(m)), primitives_[cylinders[m]].radius, std::nullopt});
      continue;
    }
    for (std::size_t j = 0; j < m && tied == m; ++j)
      if (radius_of_[cylinders[j]] == shared_by) tied = j;
    if (tied != m)
      radii.holds.push_back(
          {unit(size, radius_index(m)) - unit(size, radius_index(tied)), 0, std::nullopt});
  }
  return radii;
}

std::vector<TestedContact> Tangency::tested_contacts(const TangentLine& line,
                                                     std::span<const Contact* const> bordered,
                                                     const HeldLineFit& own) {
  const std::vector<std::size_t>& cylinders = line.cylinders;
  const Eigen::Vector3d& direction = groups_[candidates_.at(line.first).group].direction;
  const auto frame = orthonormal_pair(direction);
  const double significance2 = options_.significance * options_.significance;
  std::vector<TestedContact> tested;
  for (const Contact* contact : bordered) {
    const std::size_t m = static_cast<std::size_t>(
        std::find(cylinders.begin(), cylinders.end(), contact->cylinder) - cylinders.begin());
    const Eigen::Index radius = radius_index(m);
    const double r = own.y(radius);
    LineHold hold{Eigen::VectorXd::Zero(own.y.size()), 0, std::nullopt};
    double gap = 0, variance = 0;
    const Primitive& other = primitives_[contact->other];
    if (contact->with_plane()) {
      const Eigen::Vector3d normal = to_eigen(other.axis);
      const HeldOffset& held = offsets_.at(contact->other);
      const double offset = held.offset;
      const Eigen::Vector2d normal_in_frame = in_frame(frame, normal);
      const double distance = normal_in_frame.dot(own.y.head<2>()) - offset;
      hold.target = offset;
      hold.row.head<2>() = normal_in_frame;
      hold.row(radius) = distance < 0 ? 1 : -1;
      gap = std::abs(distance) - r;
      // The plane is uncertain too, as the held cylinder's fit below: its offset at its centroid,
      // and its normal's tilt about the axis, which moves it at the contact by the tilt times the
      // distance across from the centroid (the lever). Tilts towards the axis are left out: the
      // right angle holds them.
      const Eigen::Vector3d across_axis = direction.cross(normal);
      const double lever =
          in_frame(frame, across_axis).dot(own.y.head<2>()) - across_axis.dot(held.centroid);
      const Eigen::Matrix3d& tilt = groups_[plane_group_.at(contact->other)].covariance;
      variance = hold.row.dot(own.covariance * hold.row) + held.variance +
                 lever * lever * across_axis.dot(tilt * across_axis);
    } else {
      // The held cylinder's axis and radius are uncertain too: its own fit's covariance counts.
      const Eigen::Vector2d centre = in_frame(frame, to_eigen(other.point));
      hold = linearised(
          {Eigen::VectorXd(), 0,
           CircleHold{centre, other.radius, contact->partner_sign, contact->own_sign, radius}},
          own.y);
      gap = hold.row.dot(own.y) - hold.target;
      // Fitted once: a held cylinder no longer moves.
      auto [fitted, added] = partner_fits_.try_emplace(contact->other);
      if (added) {
        const CoaxialMember alone{points_[contact->other], weights_[contact->other], other.radius};
        fitted->second = fit_held_line(direction, centre, {&alone, 1}, {});
      }
      const std::optional<HeldLineFit>& partner = fitted->second;
      if (!partner) continue;
      Eigen::Vector3d partner_row;
      partner_row << -hold.row.head<2>(), -contact->partner_sign;
      variance = hold.row.dot(own.covariance * hold.row) +
                 partner_row.dot(partner->covariance * partner_row);
    }
    const double bound = options_.max_radius_difference * r;
    if (std::abs(gap) <= bound && significance2 * variance <= bound * bound &&
        (gap * gap <= significance2 * variance ||
         within_tolerance(std::abs(gap), options_.length_tolerance)))
      tested.push_back(
          {tolerated(gap * gap / variance, significance2, std::abs(gap), options_.length_tolerance),
           contact, m, hold});
  }
  std::sort(tested.begin(), tested.end(), [](const TestedContact& a, const TestedContact& b) {
    return std::tie(a.score, a.contact->other, a.member) <
           std::tie(b.score, b.contact->other, b.member);
  });
  return tested;
}

void Tangency::hold_tangent(const TangentLine& line, std::vector<Relation>& tangents) {
  const std::vector<std::size_t>& cylinders = line.cylinders;
  for (const std::size_t c : cylinders) settled_[c] = true;
  // Contacts with a cylinder that is still to move are left out.
  std::vector<const Contact*> bordered;
  for (const Contact& contact : contacts_)
    if (std::find(cylinders.begin(), cylinders.end(), contact.cylinder) != cylinders.end() &&
        (contact.with_plane() || !on_a_line_[contact.other] || settled_[contact.other]))
      bordered.push_back(&contact);
  if (bordered.empty()) return;
  const Eigen::Vector3d& direction = groups_[candidates_.at(line.first).group].direction;
  OwnSides sides = own_sides(cylinders, bordered);
  RadiusHolds radii = radius_holds(cylinders);
  std::vector<LineHold>& holds = radii.holds;
  const Eigen::Vector2d start =
      in_frame(orthonormal_pair(direction), to_eigen(primitives_[line.first].point));
  const std::optional<HeldLineFit> own = fit_held_line(direction, start, sides.members, holds);
  if (!own || own->free == 0) return;
  std::vector<TestedContact> tested = tested_contacts(line, bordered, *own);
  // Each trial starts from the own fit.
  for (std::size_t m = 0; m < cylinders.size(); ++m)
    sides.members[m].radius = own->y(radius_index(m));
  const std::size_t own_holds = holds.size();
  std::vector<std::pair<std::size_t, std::size_t>> kept;  // (cylinder, other)
  std::optional<HeldLineFit> fit;
  const auto try_hold = [&](const TestedContact& candidate) {
    // A condition the kept ones imply (a fragment's second face, once the line and the other
    // fragments are held) holds to round-off or not at all: it adds no freedom to test.
    const Eigen::VectorXd& at = fit ? fit->y : own->y;
    const LineHold there = linearised(candidate.hold, at);
    if (implied_by(holds, there.row, at)) {
      if (fit && std::abs(there.row.dot(fit->y) - there.target) <=
                     kImplied * fit->y(radius_index(candidate.member)))
        kept.emplace_back(cylinders[candidate.member], candidate.contact->other);
      return;
    }
    holds.push_back(candidate.hold);
    std::optional<HeldLineFit> trial =
        fit_held_line(direction, own->y.head<2>(), sides.members, holds);
    const std::size_t conditions = holds.size() - own_holds;
    if (trial && radii_within(*own, *trial, options_.max_radius_difference) &&
        residual_excess(own->rms, trial->rms, own->count,
                        chi_square_bound(options_.significance, conditions),
                        static_cast<int>(own->free), options_.length_tolerance) <= 1) {
      fit = trial;
      kept.emplace_back(cylinders[candidate.member], candidate.contact->other);
    } else {
      holds.pop_back();
    }
  };
  std::vector<const Contact*> untried = bordered;
  for (std::size_t kept_before = 0;;) {
    for (const TestedContact& candidate : tested) {
      std::erase(untried, candidate.contact);
      try_hold(candidate);
    }
    // Kept holds move the line and its radii: a fillet's radius, off alike at both faces it
    // rounds (an exact tessellation's chords), is set by the first. A contact whose gap the own
    // fit put beyond the significance is tested again at the held fit while holds are added.
    if (!fit || kept.size() == kept_before || untried.empty()) break;
    kept_before = kept.size();
    tested = tested_contacts(line, untried, *fit);
  }
  if (!fit) return;
  for (std::size_t m = 0; m < cylinders.size(); ++m) {
    Primitive& cylinder = primitives_[cylinders[m]];
    // A held or tied radius is met to round-off: its class's radius stays one set of bits.
    const std::size_t tied = radii.tied[m];
    place_cylinder(cylinder, direction, fit->y.head<2>(),
                   tied == kNoRelation ? cylinder.radius : fit->y(radius_index(tied)));
  }
  for (const auto& [c, p] : kept) {
    moved_[p] = true;
    Relation& relation = tangents.emplace_back();
    relation.kind = Relation::Kind::Tangent;
    relation.members = {std::min(c, p), std::max(c, p)};
  }
}

void Tangency::write_plane_offsets() {
  for (const auto& [p, held] : offsets_) {
    if (!moved_[p]) continue;
    const Eigen::Vector3d normal = to_eigen(primitives_[p].axis);
    const Eigen::Vector3d point = to_eigen(primitives_[p].point);
    primitives_[p].point = to_vec3(point + (held.offset - normal.dot(point)) * normal);
  }
}

// fit_held_line()'s iteration: y = (c, r₀, r₁, …), and N, the orthonormal basis of the null space
// of the holds' rows linearised at y (y = y₀ + N z).
class HeldLine {
 public:
  HeldLine(const Eigen::Vector3d& direction, const Eigen::Vector2d& centre,
           std::span<const CoaxialMember> members, std::span<const LineHold> holds)
      : members_(members),
        holds_(holds),
        size_(2 + static_cast<Eigen::Index>(members.size())),
        free_(size_ - static_cast<Eigen::Index>(holds.size())),
        curved_(std::any_of(holds.begin(), holds.end(),
                            [](const LineHold& hold) { return hold.circle.has_value(); })),
        y_(size_),
        basis_(Eigen::MatrixXd::Identity(size_, size_)),
        basis_rows_(basis_),
        projected_(members.size()),
        normal_(free_, free_),
        gradient_(free_),
        row_(free_) {
    y_.head<2>() = centre;
    for (Eigen::Index i = 2; i < size_; ++i)
      y_(i) = members[static_cast<std::size_t>(i - 2)].radius;
    const auto [u, v] = orthonormal_pair(direction);
    for (std::size_t m = 0; m < members.size(); ++m)
      for (const Vec3& p : members[m].points)
        projected_[m].emplace_back(u.dot(to_eigen(p)), v.dot(to_eigen(p)));
  }

  // Projects y onto the holds (linearised at y) and forms the basis of their null space; false
  // when they are (nearly) dependent: their rows' Gram determinant, normalised (1 for orthogonal
  // rows, 0 for dependent ones), at most 1e-12.
  bool constrain() {
    const Eigen::Index k = size_ - free_;
    if (k == 0) return true;
    Eigen::MatrixXd rows(size_, k);
    Eigen::VectorXd excess(k);
    double norms = 1;
    for (Eigen::Index i = 0; i < k; ++i) {
      const LineHold hold = linearised(holds_[static_cast<std::size_t>(i)], y_);
      rows.col(i) = hold.row;
      excess(i) = hold.row.dot(y_) - hold.target;
      norms *= hold.row.squaredNorm();
    }
    const Eigen::MatrixXd gram = rows.transpose() * rows;
    if (!(gram.determinant() > 1e-12 * norms)) return false;
    violation_ = excess.norm();
    y_ -= rows * gram.ldlt().solve(excess);
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(rows);
    basis_ = (qr.householderQ() * Eigen::MatrixXd::Identity(size_, size_)).rightCols(free_);
    basis_rows_ = basis_.transpose();
    return true;
  }

  // Gauss–Newton in z until the step is round-off and y is on the holds, a circle's hold
  // linearised again and y projected onto it at every step; false when a projection fails, a step
  // is not finite or 50 steps do not converge.
  bool solve() {
    bool converged = free_ == 0 && !curved_;
    for (int step = 0; step < 50 && !converged; ++step) {
      // A circle's hold linearised again, and y projected onto it: settled once y was on it.
      const bool projected_again = curved_ && step > 0;
      if (projected_again && !constrain()) return false;
      const bool on_holds = !projected_again || !(violation_ > 1e-14 * y_.norm());
      if (free_ == 0) {
        converged = projected_again && on_holds;
        continue;
      }
      linearise(true);
      const Eigen::VectorXd delta = normal_.ldlt().solve(-gradient_);
      if (!delta.allFinite()) return false;
      const Eigen::VectorXd move = basis_ * delta;
      y_ += move;
      converged = !(move.norm() > 1e-14 * y_.norm()) && on_holds;
    }
    return converged;
  }

  // Σ w e² and its Gauss–Newton system in z (weighted or not); returns the unweighted Σ e².
  double linearise(bool weighted) {
    normal_.setZero();
    gradient_.setZero();
    double squares = 0;
    for (std::size_t m = 0; m < members_.size(); ++m)
      for (std::size_t i = 0; i < projected_[m].size(); ++i) {
        const Eigen::Vector2d d = projected_[m][i] - y_.head<2>();
        const double length = d.norm();
        if (!(length > 0)) continue;
        const Eigen::Index radius = 2 + static_cast<Eigen::Index>(m);
        const double e = length - y_(radius), w = weighted ? members_[m].weights[i] : 1.0;
        row_.noalias() = -(d.x() / length) * basis_rows_.col(0) -
                         (d.y() / length) * basis_rows_.col(1) - basis_rows_.col(radius);
        normal_.noalias() += w * row_ * row_.transpose();
        gradient_.noalias() += (w * e) * row_;
        squares += e * e;
      }
    return squares;
  }

  const Eigen::VectorXd& y() const { return y_; }
  Eigen::Index free() const { return free_; }
  // The covariance of y for a residual variance of `variance`, from the last linearise().
  Eigen::MatrixXd covariance(double variance) const {
    return basis_ * normal_.inverse() * basis_.transpose() * variance;
  }

 private:
  std::span<const CoaxialMember> members_;
  std::span<const LineHold> holds_;
  Eigen::Index size_, free_;
  bool curved_;
  Eigen::VectorXd y_;
  Eigen::MatrixXd basis_, basis_rows_;
  double violation_ = 0;  // how far y was from the holds, linearised, before their last projection
  std::vector<std::vector<Eigen::Vector2d>> projected_;  // in orthonormal_pair(direction) coords
  Eigen::MatrixXd normal_;
  Eigen::VectorXd gradient_;
  Eigen::VectorXd row_;  // a residual's derivative in z
};

}  // namespace

std::optional<HeldLineFit> fit_held_line(const Eigen::Vector3d& direction,
                                         const Eigen::Vector2d& centre,
                                         std::span<const CoaxialMember> members,
                                         std::span<const LineHold> holds) {
  const Eigen::Index size = 2 + static_cast<Eigen::Index>(members.size());
  const Eigen::Index k = static_cast<Eigen::Index>(holds.size());
  std::size_t count = 0;
  double largest_radius = 0;
  for (const CoaxialMember& member : members) {
    count += member.points.size();
    largest_radius = std::max(largest_radius, member.radius);
  }
  if (k > size || count <= static_cast<std::size_t>(size - k)) return std::nullopt;
  HeldLine line(direction, centre, members, holds);
  if (!line.constrain() || !line.solve()) return std::nullopt;
  const Eigen::VectorXd& y = line.y();
  if (!y.allFinite() || !(y.tail(size - 2).minCoeff() > 0)) return std::nullopt;
  const double squares = line.linearise(false);
  const Eigen::Index free = line.free();
  HeldLineFit fit{y, 0, static_cast<std::size_t>(free), count, Eigen::MatrixXd::Zero(size, size)};
  const double n = static_cast<double>(count);
  fit.rms = std::max(std::sqrt(squares / n), kResolution * largest_radius);
  if (free > 0) {
    const double variance = std::max(squares / (n - static_cast<double>(free)),
                                     kResolution * kResolution * largest_radius * largest_radius);
    fit.covariance = line.covariance(variance);
    if (!fit.covariance.allFinite()) return std::nullopt;
  }
  return fit;
}

// Cylinders held tangent to the planes they border: a fillet, a slot's round end. A cylinder
// whose direction group a right angle made exactly orthogonal to a plane's (`orthogonal`, indices
// into `groups`) is tested against each plane of the other group that it borders (they share an
// inlier point). The cylinders of a Coaxial relation of `relations` (the fragments of one fillet
// the hierarchy cut apart, a counterbore's steps) are tested on their one line, together: its
// position and their radii are fitted at once, and a tangency of one moves them all. A line with
// spheres centred on it is left out.
//
// Likewise a cylinder tangent to a cylinder of its direction group that it borders, on another
// line: a fillet around a boss or inside a bore, the arcs of an extruded profile. The one with
// fewer points is refitted, the other held (as a plane is): |c − c'| = R ± r, a CircleHold,
// nonlinear in the line's position c, which fit_held_line() linearises at every step. Its band is
// where the circles part by less than the noise, √(2σ / |1/r ± 1/R|); circles of nearly one
// curvature, one inside the other, are left out. A held cylinder must be where it ends, so lines
// with such partners come after the others, the largest first, and a partner still to move is not
// held.
//
// A tangent join is a band about the contact line (the foot of the cylinder's axis on the plane,
// from its fit as it comes) where the two surfaces are within the noise of each other, and the
// hierarchy's border through it follows the noise: a point there joins the surface its noise
// moves it towards. A row of the plane's side counted in the cylinder (√(r² + t²) from its axis,
// t along the plane from the contact line) also pulls its radius up. On a noisy fillet cut by the
// hierarchy the gap between the axis's distance from a face and the radius came out up to 4
// deviations too small, and one of its two tangencies was refused in 4 draws of 30. So each side
// keeps only its points beyond the band on its own side: a choice by where points are along the
// plane, across the noise, which does not bias the fits (1 of 30). A plane's offset is
// refitted with its normal from its points beyond every candidate cylinder's band (not a coplanar
// set's shared offset). The band is as narrow as it can be, so that the points next to the
// contact line still tell a kink of a few degrees from a tangency.
//
// The gap to each plane, from the line's cylinders refitted on their points with its direction
// (a radius an EqualRadius relation shares with clusters off the line held, one shared only on
// the line one parameter), must be within the significance (its standard deviation from that
// fit's covariance, the plane's offset variance and its normal's tilt about the axis times the
// distance across from its centroid to the contact) or the length tolerance, within
// max_radius_difference of the radius and known to better than that (the interval rule of the
// spheres' centres). Candidates are tried from the nearest in standard deviations, each kept when
// the line refitted tangent to it and to those kept before (fit_held_line(): a lone cylinder keeps
// 2 parameters for one plane, 1 for two) raises its residual sum by at most the χ² bound of that
// many conditions times its residual variance (a likelihood-ratio test), or its mean square by at
// most the length tolerance's square. A condition the kept ones imply (a fragment's face once
// another fragment of the same radius is tangent to it) is kept when it holds to round-off. In that
// refit the planes are held at their offsets and normals: a face usually has far more points than a
// fillet's narrow arc. The cylinders are written back, and the planes they are tangent to with
// their refitted offsets; each pair is a Tangent relation of `tangents`.
void make_tangent(const std::vector<DirectionGroup>& groups,
                  const std::vector<std::pair<std::size_t, std::size_t>>& orthogonal,
                  const std::vector<std::vector<std::size_t>>& refitted,
                  const RegularityOptions& options, std::vector<Primitive>& primitives,
                  const std::vector<std::vector<Vec3>>& points,
                  const std::vector<std::vector<double>>& weights,
                  const std::vector<Relation>& relations, std::vector<Relation>& tangents) {
  Tangency tangency(groups, options, primitives, points, weights, relations);
  tangency.find_candidates(orthogonal, refitted);
  tangency.find_contacts();
  tangency.fit_plane_offsets();
  for (const TangentLine& line : tangency.lines_in_order()) tangency.hold_tangent(line, tangents);
  tangency.write_plane_offsets();
}

}  // namespace primseg::detail
