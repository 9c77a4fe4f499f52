// detail::regularize's tangencies (src/regularity/tangency.cpp): fillets held tangent to the
// faces and the bosses or bores they round, exactly, and nothing held where a round meets its
// neighbours at a kink or is set off them.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "eigen_conversions.hpp"
#include "regularity.hpp"
#include "regularity/stages.hpp"
#include "support/regularity_shapes.hpp"

namespace primseg {
namespace {

using detail::to_eigen;
using testing::angle_between_lines;
using testing::axis_offset;
using testing::Cluster;
using testing::fitted_cylinder;
using testing::fitted_plane;
using testing::has_relation;
using testing::Kind;
using testing::profile_arc;
using testing::profile_line;
using testing::regularize;
using testing::Relations;
using testing::swept_profile;
using testing::with_tolerances;

// The distance of a cylinder's axis line from a plane (the axis parallel to the plane).
double axis_to_plane(const Primitive& cylinder, const Primitive& plane) {
  return std::abs(to_eigen(plane.axis).dot(to_eigen(cylinder.point) - to_eigen(plane.point)));
}

// A box's edge along y rounded by a quarter cylinder of radius 0.2 (axis through x = z = -0.2)
// between its side x = 0 and its top z = 0, noise 0.002: side, fillet, top.
constexpr double kRoundedEdgeRadius = 0.2;
const Eigen::Vector3d kRoundedEdgeAxisPoint(-kRoundedEdgeRadius, 0, -kRoundedEdgeRadius);

std::vector<Cluster> rounded_edge(std::uint64_t seed) {
  constexpr double r = kRoundedEdgeRadius;
  std::mt19937_64 rng(seed);
  return swept_profile(
      {profile_line({0, -1.2}, {0, -r}, {1, 0}, 20), profile_arc({-r, -r}, r, 0, 90, 12),
       profile_line({-r, 0}, {-1.2, 0}, {0, 1}, 20)},
      0.002, rng);
}

// Over `draws` draws, a fillet tangent (to both of its neighbours) in `tangent_draws`: nearly
// every one, since each of the two tests fails as rarely as a 3-sigma deviation, and its radius's
// RMS error below its own fit's over `gain` (the sums of squares over all draws and over the
// tangent ones).
void expect_held_in_nearly_every_draw(const std::string& what, int draws, int tangent_draws,
                                      double own_squares, double tangent_squares, double gain) {
  EXPECT_GE(tangent_draws, draws - 1);
  const double own = std::sqrt(own_squares / draws);
  const double tangent = std::sqrt(tangent_squares / tangent_draws);
  std::printf("%s: tangent in %d of %d draws, radius RMS error: own %.3g, tangent %.3g\n",
              what.c_str(), tangent_draws, draws, own, tangent);
  EXPECT_LT(tangent, own / gain);
}

// Over 20 draws of the rounded edge, its fillet whole (`fragments` 1) or cut across its axis into
// two clusters (y < 0 and y >= 0), as the hierarchy cuts long blends (the fragments share one axis
// line, and the line and the radius are held by both faces): every fillet cluster is tangent to
// both faces in nearly every draw, exactly, and its radius is known far better than from a
// cluster's own fit.
void expect_fillet_tangent_to_both_faces(std::size_t fragments) {
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  double own_squares = 0, tangent_squares = 0;
  int tangent_draws = 0;
  constexpr int kDraws = 20;
  for (std::uint64_t seed = 1; seed <= kDraws; ++seed) {
    SCOPED_TRACE(seed);
    const std::vector<Cluster> profile = rounded_edge(seed);
    std::vector<Cluster> clusters(fragments + 2);
    clusters.front() = profile[0];
    clusters.back() = profile[2];
    for (std::size_t i = 0; i < profile[1].points.size(); ++i) {
      Cluster& fragment = clusters[fragments == 1 || profile[1].points[i][1] < 0 ? 1 : 2];
      fragment.points.push_back(profile[1].points[i]);
      fragment.weights.push_back(profile[1].weights[i]);
    }
    const std::size_t top = fragments + 1;
    std::vector<Primitive> primitives{fitted_plane(clusters[0])};
    for (std::size_t f = 1; f < top; ++f)
      primitives.push_back(
          fitted_cylinder(clusters[f], y, kRoundedEdgeAxisPoint, kRoundedEdgeRadius));
    primitives.push_back(fitted_plane(clusters[top]));
    own_squares += std::pow(primitives[1].radius - kRoundedEdgeRadius, 2);
    const Relations relations = regularize(primitives, clusters);
    const auto has = [&](Kind kind, std::vector<std::size_t> members) {
      return std::count(relations.begin(), relations.end(),
                        std::pair<Kind, std::vector<std::size_t>>{kind, members}) == 1;
    };
    if (fragments == 2) {
      ASSERT_TRUE(has(Kind::Coaxial, {1, 2}));
    }
    bool all_tangent = true;
    for (std::size_t f = 1; f < top; ++f)
      all_tangent = all_tangent && has(Kind::Tangent, {0, f}) && has(Kind::Tangent, {f, top});
    if (!all_tangent) continue;
    ++tangent_draws;
    tangent_squares += std::pow(primitives[1].radius - kRoundedEdgeRadius, 2);
    // Exactly tangent: each fillet cluster's axis along both faces, at the radius from each, and
    // the fragments still on one line.
    for (std::size_t f = 1; f < top; ++f) {
      EXPECT_LE(axis_offset(primitives[f], primitives[1]), 1e-14);
      EXPECT_LE(angle_between_lines(primitives[f].axis, primitives[1].axis), 1e-14);
      for (const std::size_t plane : {std::size_t{0}, top}) {
        EXPECT_NEAR(to_eigen(primitives[f].axis).dot(to_eigen(primitives[plane].axis)), 0, 1e-14);
        EXPECT_NEAR(axis_to_plane(primitives[f], primitives[plane]), primitives[f].radius, 1e-14);
      }
    }
  }
  // Held by its faces, the fillet's narrow arc is known far better.
  expect_held_in_nearly_every_draw("fillet in " + std::to_string(fragments) + " cluster(s)", kDraws,
                                   tangent_draws, own_squares, tangent_squares, 2);
}

TEST(Regularity, CirclesTouchAtTheSumOrTheDifferenceOfTheirRadii) {
  // distance_across: the lines through two points along a direction, whatever the points'
  // positions along it.
  const Eigen::Vector3d direction = Eigen::Vector3d(1, 2, 2) / 3;
  const Eigen::Vector3d across = Eigen::Vector3d(2, -1, 0).normalized();
  EXPECT_NEAR(detail::distance_across(0.7 * across + 5 * direction, direction), 0.7, 1e-15);
  // A fillet of radius 0.1 held to a boss of radius 0.5: outside it (+1, +1) at 0.6, inside a
  // bore of that radius (+1, −1) at 0.4, around a pin of radius 0.05 from inside (−1, +1) at
  // 0.05; the gap is the distance's excess over the nearest of these.
  const auto expect_contact = [](double distance, double radius, double held, double partner_sign,
                                 double own_sign, double gap) {
    const detail::CircleContact contact = detail::nearest_circle_contact(distance, radius, held);
    EXPECT_EQ(contact.partner_sign, partner_sign) << distance;
    EXPECT_EQ(contact.own_sign, own_sign) << distance;
    EXPECT_NEAR(contact.gap, gap, 1e-15) << distance;
  };
  expect_contact(0.61, 0.1, 0.5, 1, 1, 0.01);
  expect_contact(0.59, 0.1, 0.5, 1, 1, -0.01);
  expect_contact(0.41, 0.1, 0.5, 1, -1, 0.01);
  expect_contact(0.38, 0.1, 0.5, 1, -1, -0.02);
  expect_contact(0.06, 0.1, 0.05, -1, 1, 0.01);
  // Halfway between the sum and the difference, the sum (each outside the other) wins the tie.
  expect_contact(0.5, 0.1, 0.5, 1, 1, -0.1);
}

TEST(Regularity, AFilletIsHeldTangentToBothFacesItRounds) {
  expect_fillet_tangent_to_both_faces(1);
}

TEST(Regularity, AFilletCutInTwoIsTangentToBothFacesOnOneLine) {
  // A radius shared only by the fragments is fitted with their line, not held at the value the
  // equal-radius step fitted to the same points (which refused a face in 4 draws of 20).
  expect_fillet_tangent_to_both_faces(2);
}

TEST(Regularity, ASlotsRoundEndIsTangentToBothSides) {
  // A slot's end: its sides x = ±0.15 joined by a half cylinder of radius 0.15 about the y axis.
  constexpr double kRoundRadius = 0.15, kSigma = 0.002;
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE(seed);
    std::mt19937_64 rng(seed);
    const std::vector<Cluster> clusters =
        swept_profile({profile_line({kRoundRadius, -1}, {kRoundRadius, 0}, {-1, 0}, 20),
                       profile_arc({0, 0}, kRoundRadius, 0, 180, 18),
                       profile_line({-kRoundRadius, 0}, {-kRoundRadius, -1}, {1, 0}, 20)},
                      kSigma, rng);
    std::vector<Primitive> primitives{fitted_plane(clusters[0]),
                                      fitted_cylinder(clusters[1], y, {0, 0, 0}, kRoundRadius),
                                      fitted_plane(clusters[2])};
    const Relations relations = regularize(primitives, clusters);
    EXPECT_EQ(std::count(relations.begin(), relations.end(),
                         std::pair<Kind, std::vector<std::size_t>>{Kind::Tangent, {0, 1}}),
              1);
    EXPECT_EQ(std::count(relations.begin(), relations.end(),
                         std::pair<Kind, std::vector<std::size_t>>{Kind::Tangent, {1, 2}}),
              1);
    // Its radius is half the sides' distance, its axis midway between them.
    EXPECT_NEAR(axis_to_plane(primitives[1], primitives[0]), primitives[1].radius, 1e-14);
    EXPECT_NEAR(axis_to_plane(primitives[1], primitives[2]), primitives[1].radius, 1e-14);
    EXPECT_NEAR(primitives[1].radius, kRoundRadius, 0.002);
  }
}

TEST(Regularity, ARoundMeetingItsFacesAtAKinkIsNotTangentToThem) {
  // As the fillet above, but its arc spans 10 to 80 degrees and the faces go on from its ends:
  // each face is r cos 10° from the axis, 1.5% of the radius (0.003, within max_radius_difference)
  // short of it, with a kink of 10 degrees at each border.
  constexpr double kRoundRadius = 0.2, kSigma = 0.002;
  const Eigen::Vector2d centre(-kRoundRadius, -kRoundRadius);
  const double degree = std::numbers::pi / 180;
  const Eigen::Vector2d start =
      centre + kRoundRadius * Eigen::Vector2d(std::cos(10 * degree), std::sin(10 * degree));
  const Eigen::Vector2d end =
      centre + kRoundRadius * Eigen::Vector2d(std::cos(80 * degree), std::sin(80 * degree));
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE(seed);
    std::mt19937_64 rng(seed);
    const std::vector<Cluster> clusters =
        swept_profile({profile_line({start.x(), -1.2}, start, {1, 0}, 20),
                       profile_arc(centre, kRoundRadius, 10, 80, 12),
                       profile_line(end, {-1.2, end.y()}, {0, 1}, 20)},
                      kSigma, rng);
    std::vector<Primitive> primitives{
        fitted_plane(clusters[0]),
        fitted_cylinder(clusters[1], y, {centre.x(), 0, centre.y()}, kRoundRadius),
        fitted_plane(clusters[2])};
    for (const auto& [kind, members] : regularize(primitives, clusters))
      EXPECT_NE(kind, Kind::Tangent);
  }
}

// A profile swept along y: an arc of a circle of radius `big_radius` about `big_centre` (the
// boss or the bore, cluster 0), a fillet of radius `radius` about `centre` tangent to it (cluster
// 1) and to the line z = `plate` it runs into (cluster 2, towards x = `plate_end`). The fillet's
// arc runs from its contact with the circle to its contact with the line; `internal` puts it
// inside the circle. `shift` moves the fillet's centre away from the circle's (a step, not a
// tangency). Noise 0.001 along the normals.
struct FilletOnACircle {
  double big_radius, radius, plate, plate_end;
  bool internal;
  double shift = 0, noise = 0.001;

  double distance() const { return internal ? big_radius - radius : big_radius + radius; }
  // The fillet's centre: at the radius from the line, at distance() from the circle's centre.
  Eigen::Vector2d centre() const {
    const double z = internal ? plate - radius : plate + radius;
    return {std::sqrt(distance() * distance() - z * z) + shift, z};
  }
  std::vector<Cluster> clusters(std::uint64_t seed) const {
    std::mt19937_64 rng(seed);
    const Eigen::Vector2d c = centre();
    const double degrees = 180 / std::numbers::pi;
    const double towards = std::atan2(c.y(), c.x() - shift) * degrees;  // the contact's direction
    const double from = internal ? -90 : 90;
    return swept_profile(
        {profile_arc({0, 0}, big_radius, from, towards, 24),
         profile_arc(c, radius, internal ? towards : towards + 180, internal ? 90 : 270, 12),
         profile_line({c.x(), plate}, {plate_end, plate}, {0, 1}, 20)},
        noise, rng);
  }
  // Each cluster's own fit: the circle's, the fillet's, the line's.
  std::vector<Primitive> fits(const std::vector<Cluster>& clusters) const {
    const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
    const Eigen::Vector2d c = centre();
    return {fitted_cylinder(clusters[0], y, {0, 0, 0}, big_radius),
            fitted_cylinder(clusters[1], y, {c.x(), 0, c.y()}, radius), fitted_plane(clusters[2])};
  }
};

// Over 20 draws: the circle (more points) is held, and the fillet is made tangent to it and to
// the line in nearly every draw, exactly, its radius known better than from its own fit (less so
// than between two faces: the circle's own error is in it).
void expect_fillet_tangent_to_circle_and_line(const FilletOnACircle& shape) {
  double own_squares = 0, tangent_squares = 0;
  int tangent_draws = 0;
  constexpr int kDraws = 20;
  for (std::uint64_t seed = 1; seed <= kDraws; ++seed) {
    SCOPED_TRACE(seed);
    const std::vector<Cluster> clusters = shape.clusters(seed);
    std::vector<Primitive> primitives = shape.fits(clusters);
    own_squares += std::pow(primitives[1].radius - shape.radius, 2);
    // Where the relations before the tangencies put the circle, which holds it.
    std::vector<Primitive> held = primitives;
    detail::RegularityOptions no_tangency;
    no_tangency.tangency = false;
    regularize(held, clusters, no_tangency);
    const Relations relations = regularize(primitives, clusters);
    ASSERT_TRUE(has_relation(relations, Kind::Parallel, {0, 1}));
    if (!has_relation(relations, Kind::Tangent, {0, 1}) ||
        !has_relation(relations, Kind::Tangent, {1, 2}))
      continue;
    ++tangent_draws;
    tangent_squares += std::pow(primitives[1].radius - shape.radius, 2);
    // The circle is held where the other relations put it; the fillet's axis is at the sum
    // (outside) or the difference (inside) of the radii from its axis and at its radius from the
    // line.
    EXPECT_EQ(primitives[0].radius, held[0].radius);
    EXPECT_EQ(primitives[0].point, held[0].point);
    const double r = primitives[1].radius, big = primitives[0].radius;
    EXPECT_NEAR(axis_offset(primitives[1], primitives[0]), shape.internal ? big - r : big + r,
                1e-14);
    EXPECT_NEAR(axis_to_plane(primitives[1], primitives[2]), r, 1e-14);
  }
  expect_held_in_nearly_every_draw(
      shape.internal ? "fillet inside a circle" : "fillet outside a circle", kDraws, tangent_draws,
      own_squares, tangent_squares, 1.4);
}

TEST(Regularity, AFilletIsHeldTangentToTheBossItRounds) {
  // A boss of radius 0.5 meets a plate 0.3 below its axis through a fillet of radius 0.2.
  expect_fillet_tangent_to_circle_and_line({0.5, 0.2, -0.3, 1.8, false});
}

TEST(Regularity, AFilletIsHeldTangentToTheBoreItRounds) {
  // A bore of radius 0.5 meets a face 0.2 above its axis through a fillet of radius 0.1 inside.
  expect_fillet_tangent_to_circle_and_line({0.5, 0.1, 0.2, -0.8, true});
}

// The root mean square distance of `cluster`'s points from `primitive`.
double rms_distance(const Primitive& primitive, const Cluster& cluster) {
  double squares = 0;
  for (const Vec3& x : cluster.points) squares += std::pow(primitive.distance(x), 2);
  return std::sqrt(squares / static_cast<double>(cluster.points.size()));
}

TEST(Regularity, TangentCylindersAreExactWheneverFound) {
  // 120 random fillets on circles, outside and inside, exact and noisy, some set off the circle by
  // up to 2% of their radius. Whenever the fillet is made tangent to the circle, it is so to
  // round-off, the circle is where the other relations put it, and the fillet's fit is not much
  // worse for it; every exact one that touches its circle is found tangent to it.
  std::mt19937_64 rng(35);
  std::uniform_real_distribution<double> unit(0, 1);
  int exact = 0, found = 0;
  for (int trial = 0; trial < 120; ++trial) {
    SCOPED_TRACE(trial);
    FilletOnACircle shape{0.3 + 0.7 * unit(rng), 0, 0, 0, trial % 2 == 1};
    shape.radius = shape.big_radius * (0.05 + 0.4 * unit(rng));
    const double degree = std::numbers::pi / 180;
    const double height = shape.distance() * std::sin((-60 + 120 * unit(rng)) * degree);
    shape.plate = shape.internal ? height + shape.radius : height - shape.radius;
    shape.plate_end = shape.centre().x() + (shape.internal ? -1 : 1);
    shape.noise = std::array{0.0, 0.0005, 0.002}[trial % 3];
    if (trial % 4 == 3) shape.shift = 0.02 * shape.radius * (2 * unit(rng) - 1);
    const std::vector<Cluster> clusters = shape.clusters(static_cast<std::uint64_t>(trial));
    std::vector<Primitive> primitives = shape.fits(clusters);
    const double own_rms = rms_distance(primitives[1], clusters[1]);
    std::vector<Primitive> held = primitives;
    detail::RegularityOptions no_tangency;
    no_tangency.tangency = false;
    regularize(held, clusters, no_tangency);
    const Relations relations = regularize(primitives, clusters);
    const bool touching = shape.noise == 0 && shape.shift == 0;
    exact += touching;
    if (!has_relation(relations, Kind::Tangent, {0, 1})) {
      EXPECT_FALSE(touching) << "an exact fillet on its circle";
      continue;
    }
    found += touching;
    EXPECT_EQ(primitives[0].radius, held[0].radius);
    EXPECT_EQ(primitives[0].point, held[0].point);
    const double r = primitives[1].radius, big = primitives[0].radius;
    EXPECT_NEAR(axis_offset(primitives[1], primitives[0]), shape.internal ? big - r : big + r,
                1e-13);
    EXPECT_LE(rms_distance(primitives[1], clusters[1]), 1.25 * own_rms + 1e-9);
  }
  std::printf("exact fillets on their circle: %d of %d found tangent\n", found, exact);
  EXPECT_GT(exact, 10);
}

TEST(Regularity, AFilletSetOffTheBossIsNotTangentToIt) {
  // As the boss's fillet above, moved 0.003 away from the boss along x: a gap of 0.003 (1.5% of
  // its radius, within max_radius_difference) at their border, tangent to the plate still.
  const FilletOnACircle shape{0.5, 0.2, -0.3, 1.8, false, 0.003};
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE(seed);
    const std::vector<Cluster> clusters = shape.clusters(seed);
    std::vector<Primitive> primitives = shape.fits(clusters);
    const Relations relations = regularize(primitives, clusters);
    EXPECT_FALSE(has_relation(relations, Kind::Tangent, {0, 1}));
    EXPECT_TRUE(has_relation(relations, Kind::Tangent, {1, 2}));
  }
}

TEST(Regularity, ALengthToleranceMakesAnExactFilletOffByLessThanItTangent) {
  // The rounded edge, exact, with its fillet's axis 1e-4 farther from the side than its radius
  // (a kink of 1e-4 at that border) and exactly its radius from the top: tangent to the top
  // within the significance, and to the side too only within a length tolerance above 1e-4.
  constexpr double r = kRoundedEdgeRadius, kGap = 1e-4;
  std::mt19937_64 rng(1);
  const std::vector<Cluster> clusters = swept_profile(
      {profile_line({0, -1.2}, {0, -r}, {1, 0}, 20), profile_arc({-r - kGap, -r}, r, 0, 90, 12),
       profile_line({-r - kGap, 0}, {-1.2, 0}, {0, 1}, 20)},
      0, rng);
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  const std::vector<Primitive> fitted{fitted_plane(clusters[0]),
                                      fitted_cylinder(clusters[1], y, {-r - kGap, 0, -r}, r),
                                      fitted_plane(clusters[2])};
  for (const double tolerance : {0.0, 1e-5}) {
    SCOPED_TRACE(tolerance);
    std::vector<Primitive> primitives = fitted;
    const Relations relations = regularize(primitives, clusters, with_tolerances(0, tolerance));
    EXPECT_TRUE(has_relation(relations, Kind::Tangent, {1, 2}));
    EXPECT_FALSE(has_relation(relations, Kind::Tangent, {0, 1}));
  }
  std::vector<Primitive> primitives = fitted;
  constexpr double kTolerance = 2 * kGap;
  const Relations relations = regularize(primitives, clusters, with_tolerances(0, kTolerance));
  EXPECT_TRUE(has_relation(relations, Kind::Tangent, {0, 1}));
  EXPECT_TRUE(has_relation(relations, Kind::Tangent, {1, 2}));
  for (const std::size_t plane : {std::size_t{0}, std::size_t{2}})
    EXPECT_NEAR(axis_to_plane(primitives[1], primitives[plane]), primitives[1].radius, 1e-14);
  // The tangent fillet is within the tolerance of its points (RMS).
  EXPECT_LE(rms_distance(primitives[1], clusters[1]), kTolerance);
}

}  // namespace
}  // namespace primseg
