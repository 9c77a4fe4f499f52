// The uncertainties every test of regularize() weighs differences by, against Monte Carlo: a
// plane's and a cylinder's tilt covariance (src/regularity/directions.cpp), the covariance of the
// joint fits' line positions, sphere positions and radii (src/regularity/joint_fit.cpp), and that
// of a fillet's line and radius, free or held tangent (src/regularity/tangency.cpp). Over
// many noisy draws of one shape, each estimate's squared error in units of its own predicted
// covariance must average its degrees of freedom: an overconfident covariance would relate
// nothing, an underconfident one everything. And on exact points the fits are exact.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <random>
#include <vector>

#include "eigen_conversions.hpp"
#include "orthonormal_pair.hpp"
#include "regularity/stages.hpp"
#include "support/regularity_shapes.hpp"

namespace primseg {
namespace {

using detail::to_eigen;
using detail::to_vec3;
using testing::Cluster;
using testing::fitted_cylinder;
using testing::noisy_cylinder;
using testing::noisy_plane;
using testing::noisy_sphere_cap;

constexpr int kDraws = 400;

// The mean of χ² values of k degrees of freedom over kDraws draws is k within 4 standard errors
// (√(2k / kDraws) each).
void expect_calibrated(double sum, int freedom, const char* what) {
  const double mean = sum / kDraws, error = std::sqrt(2.0 * freedom / kDraws);
  std::printf("%s: mean squared error in its own deviations %.3f (expected %d)\n", what, mean,
              freedom);
  EXPECT_NEAR(mean, freedom, 4 * error) << what;
}

// δᵀ C⁻¹ δ for a tilt δ from the truth in an item's frame.
double tilt_chi_square(const detail::Oriented& item, const Eigen::Vector3d& truth) {
  const Eigen::Vector3d direction =
      item.direction.dot(truth) < 0 ? -item.direction : item.direction;
  const Eigen::Vector2d tilt = item.frame.transpose() * (direction - truth);
  return tilt.dot(item.covariance.inverse() * tilt);
}

TEST(RegularityUncertainty, APlanesTiltCovarianceIsCalibrated) {
  const Eigen::Vector3d normal = Eigen::Vector3d(1, -2, 2).normalized();
  std::mt19937_64 rng(11);
  double sum = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const Cluster plane = noisy_plane(normal, {0.3, 0.1, -0.2}, 2, 0.01, rng);
    const std::optional<detail::Oriented> item = detail::oriented_plane(0, plane.points);
    ASSERT_TRUE(item);
    sum += tilt_chi_square(*item, normal);
  }
  expect_calibrated(sum, 2, "plane tilt");
}

TEST(RegularityUncertainty, APlanesOffsetVarianceIsCalibrated) {
  // The offset along a known direction, from unequal weights (σ̂² Σw² / (Σw)²).
  const Eigen::Vector3d normal = Eigen::Vector3d(2, 1, -2).normalized(), centre(0.5, -0.3, 0.8);
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> weight(0.2, 3);
  double sum = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    Cluster plane = noisy_plane(normal, centre, 2, 0.01, rng, 6);
    for (double& w : plane.weights) w = weight(rng);
    const std::optional<detail::AlignedPlane> aligned =
        detail::aligned_plane(0, normal, plane.points, plane.weights);
    ASSERT_TRUE(aligned);
    sum += std::pow(aligned->offset - normal.dot(centre), 2) / aligned->variance;
  }
  expect_calibrated(sum, 1, "plane offset");
}

// Over kDraws cylinders of radius 0.5 with noise 0.005 (drawn from `seed`), the χ² of each axis's
// tilt in its own covariance must average 2.
void expect_cylinder_tilts_calibrated(const Eigen::Vector3d& axis, const Eigen::Vector3d& centre,
                                      double length, int rings, std::uint64_t seed,
                                      const char* what) {
  std::mt19937_64 rng(seed);
  double sum = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const Cluster cylinder = noisy_cylinder(axis, centre, 0.5, length, 0.005, rng, rings);
    const Primitive fit = fitted_cylinder(cylinder, axis, centre, 0.5);
    const std::optional<detail::Oriented> item = detail::oriented_cylinder(0, fit, cylinder.points);
    ASSERT_TRUE(item);
    sum += tilt_chi_square(*item, axis);
  }
  expect_calibrated(sum, 2, what);
}

TEST(RegularityUncertainty, ACylindersAxisCovarianceIsCalibrated) {
  expect_cylinder_tilts_calibrated(Eigen::Vector3d(0.2, 1, 0.1).normalized(), {1, 0, 0}, 2, 20, 12,
                                   "cylinder axis tilt");
}

TEST(RegularityUncertainty, AShortCylindersAxisCovarianceIsCalibrated) {
  // A step of a shaft: 6 rings over a length of 0.4 radii, where the tilt is known least and the
  // residuals' linearisation is at its worst. Over 20,000 draws of one along z its mean is 2.06 ±
  // 0.014, of which 0.03 is the variance being estimated from the 144 residuals (Hotelling's T²,
  // mean 2 (n − 5) / (n − 7)).
  expect_cylinder_tilts_calibrated(Eigen::Vector3d(-0.3, 0.1, 1).normalized(), {0, 0.4, 0}, 0.2, 6,
                                   17, "short cylinder axis tilt");
}

TEST(RegularityUncertainty, ACoaxialFitsLineAndRadiiCovarianceIsCalibrated) {
  // Two steps of a shaft on one line: the line's position and both radii.
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ(), centre(0.2, -0.1, 0);
  const auto [u, v] = detail::orthonormal_pair(axis);
  const Eigen::Vector2d truth(u.dot(centre), v.dot(centre));
  std::mt19937_64 rng(13);
  double line_sum = 0, radius_sum = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const Cluster thin =
        noisy_cylinder(axis, centre + Eigen::Vector3d(0, 0, -1), 0.3, 1, 0.004, rng, 8);
    const Cluster thick =
        noisy_cylinder(axis, centre + Eigen::Vector3d(0, 0, 1), 0.6, 1, 0.004, rng, 8);
    const detail::CoaxialMember members[] = {{thin.points, thin.weights, 0.31},
                                             {thick.points, thick.weights, 0.59}};
    const std::optional<detail::CoaxialFit> fit =
        detail::fit_coaxial(axis, truth + Eigen::Vector2d(0.01, -0.01), members);
    ASSERT_TRUE(fit);
    const Eigen::Vector2d error = fit->centre - truth;
    line_sum += error.dot(fit->centre_covariance.inverse() * error);
    radius_sum += std::pow(fit->radii[0] - 0.3, 2) / fit->radius_variances[0] +
                  std::pow(fit->radii[1] - 0.6, 2) / fit->radius_variances[1];
  }
  expect_calibrated(line_sum, 2, "coaxial line position");
  expect_calibrated(radius_sum, 2, "coaxial radii");
}

TEST(RegularityUncertainty, ASphereOnALineIsCalibratedAlongItAndInItsRadius) {
  // A shaft closed by a ball end centred on its axis: the sphere's position along the line and
  // its radius, with the line's position, in one fit (x = (line, position along it, radii)).
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  std::mt19937_64 rng(14);
  double sum = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const Cluster shaft = noisy_cylinder(axis, Eigen::Vector3d::Zero(), 0.4, 2, 0.004, rng, 10);
    const Cluster ball = noisy_sphere_cap({0, 0, 1}, 0.5, axis, 1.2, 0.004, rng);
    const Eigen::Vector3d direction = axis;
    const Eigen::Vector2d line(0.005, -0.005);
    const Eigen::Vector3d sphere_centre(0, 0, 1.01);
    const double radii[] = {0.41, 0.49};
    const detail::CylinderTerm terms[] = {{shaft.points, shaft.weights, 0, 0}};
    const detail::SphereTerm spheres[] = {{ball.points, ball.weights, 1, 0}};
    const std::optional<detail::JointFit> fit = detail::fit_cylinders_and_spheres(
        {&direction, 1}, {&line, 1}, {&sphere_centre, 1}, radii, terms, spheres, true);
    ASSERT_TRUE(fit);
    ASSERT_EQ(fit->covariance.rows(), 5);
    // (line u, line v, position along it, radius 0, radius 1) against the truth.
    Eigen::Matrix<double, 5, 1> error;
    error << fit->centres[0].x(), fit->centres[0].y(), fit->sphere_centres[0].dot(axis) - 1,
        fit->radii[0] - 0.4, fit->radii[1] - 0.5;
    sum += error.dot(fit->covariance.inverse() * error);
  }
  expect_calibrated(sum, 5, "cylinder and sphere on its line");
}

TEST(RegularityUncertainty, ConcentricSpheresOnALineAreCalibrated) {
  // A shaft closed by a ball end, and a socket around the ball with its centre: one position along
  // the line for both spheres (x = (line, the centre's position along it, radii)).
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 2).normalized();
  const auto [u, v] = detail::orthonormal_pair(axis);
  std::mt19937_64 rng(17);
  double sum = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const Cluster shaft = noisy_cylinder(axis, Eigen::Vector3d::Zero(), 0.4, 2, 0.004, rng, 10);
    const Cluster ball = noisy_sphere_cap(axis, 0.5, axis, 1.2, 0.004, rng);
    const Cluster socket = noisy_sphere_cap(axis, 0.7, -axis, 0.8, 0.004, rng);
    const Eigen::Vector2d line(0.005, -0.005);
    const Eigen::Vector3d centre = 1.01 * axis;
    const double radii[] = {0.41, 0.49, 0.72};
    const detail::CylinderTerm terms[] = {{shaft.points, shaft.weights, 0, 0}};
    const detail::SphereTerm spheres[] = {{ball.points, ball.weights, 1, 0, 0},
                                          {socket.points, socket.weights, 2, 0, 0}};
    const std::optional<detail::JointFit> fit = detail::fit_cylinders_and_spheres(
        {&axis, 1}, {&line, 1}, {&centre, 1}, radii, terms, spheres, true);
    ASSERT_TRUE(fit);
    ASSERT_EQ(fit->covariance.rows(), 6);
    ASSERT_EQ(fit->sphere_centres.size(), 1);
    Eigen::Matrix<double, 6, 1> error;
    error << fit->centres[0].x(), fit->centres[0].y(), fit->sphere_centres[0].dot(axis) - 1,
        fit->radii[0] - 0.4, fit->radii[1] - 0.5, fit->radii[2] - 0.7;
    sum += error.dot(fit->covariance.inverse() * error);
    // The shared centre is on the line.
    EXPECT_NEAR(u.dot(fit->sphere_centres[0]), fit->centres[0].x(), 1e-12);
    EXPECT_NEAR(v.dot(fit->sphere_centres[0]), fit->centres[0].y(), 1e-12);
  }
  expect_calibrated(sum, 6, "concentric spheres on a cylinder's line");
}

TEST(RegularityUncertainty, SpheresOfOneCentreNeedOneLine) {
  std::mt19937_64 rng(18);
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  const Cluster shaft = noisy_cylinder(axis, Eigen::Vector3d::Zero(), 0.4, 2, 0, rng, 10);
  const Cluster ball = noisy_sphere_cap(axis, 0.5, axis, 1.2, 0, rng);
  const Cluster socket = noisy_sphere_cap(axis, 0.7, -axis, 0.8, 0, rng);
  const Eigen::Vector2d line(0, 0);
  const Eigen::Vector3d centres[] = {axis, axis};
  const double radii[] = {0.4, 0.5, 0.7};
  const detail::CylinderTerm terms[] = {{shaft.points, shaft.weights, 0, 0}};
  // One centre, one sphere on the line and one free: no fit.
  const detail::SphereTerm mixed[] = {{ball.points, ball.weights, 1, 0, 0},
                                      {socket.points, socket.weights, 2, detail::kNoLine, 0}};
  EXPECT_FALSE(detail::fit_cylinders_and_spheres({&axis, 1}, {&line, 1}, {centres, 1}, radii, terms,
                                                 mixed, false));
  // A centre that is not there: no fit.
  const detail::SphereTerm beyond[] = {{ball.points, ball.weights, 1, 0, 1}};
  EXPECT_FALSE(detail::fit_cylinders_and_spheres({&axis, 1}, {&line, 1}, {centres, 1}, radii, terms,
                                                 beyond, false));
  // A centre no sphere has: no fit.
  const detail::SphereTerm one_centre[] = {{ball.points, ball.weights, 1, 0, 0},
                                           {socket.points, socket.weights, 2, 0, 0}};
  EXPECT_FALSE(detail::fit_cylinders_and_spheres({&axis, 1}, {&line, 1}, centres, radii, terms,
                                                 one_centre, false));
  // On exact points, the shared centre and the radii are exact.
  const std::optional<detail::JointFit> fit = detail::fit_cylinders_and_spheres(
      {&axis, 1}, {&line, 1}, {centres, 1}, radii, terms, one_centre, false);
  ASSERT_TRUE(fit);
  EXPECT_LT((fit->sphere_centres[0] - axis).norm(), 1e-12);
  EXPECT_NEAR(fit->radii[1], 0.5, 1e-12);
  EXPECT_NEAR(fit->radii[2], 0.7, 1e-12);
}

TEST(RegularityUncertainty, JointFitsAreExactOnExactPoints) {
  // Three holes of one radius on three lines and a free sphere of that radius: one radius.
  const Eigen::Vector3d axis = Eigen::Vector3d(0, 1, 1).normalized();
  const auto [u, v] = detail::orthonormal_pair(axis);
  std::mt19937_64 rng(15);
  std::vector<Cluster> holes;
  std::vector<Eigen::Vector2d> truths, starts;
  for (int h = 0; h < 3; ++h) {
    const Eigen::Vector3d centre = (0.9 * h) * u + (0.3 * h - 0.2) * v;
    holes.push_back(noisy_cylinder(axis, centre, 0.25, 1, 0, rng, 6));
    truths.emplace_back(u.dot(centre), v.dot(centre));
    starts.push_back(truths.back() + Eigen::Vector2d(0.01, 0.02));
  }
  const Eigen::Vector3d ball_centre(2, 1, -1);
  const Cluster ball = noisy_sphere_cap(ball_centre, 0.25, Eigen::Vector3d::UnitX(), 1, 0, rng);
  std::vector<detail::CylinderTerm> terms;
  std::vector<Eigen::Vector3d> directions(3, axis);
  for (std::size_t h = 0; h < 3; ++h) terms.push_back({holes[h].points, holes[h].weights, h, 0});
  const detail::SphereTerm spheres[] = {{ball.points, ball.weights, 0, detail::kNoLine}};
  const Eigen::Vector3d ball_start = ball_centre + Eigen::Vector3d(0.01, 0, 0.01);
  const double radius_start = 0.27;
  const std::optional<detail::JointFit> fit = detail::fit_cylinders_and_spheres(
      directions, starts, {&ball_start, 1}, {&radius_start, 1}, terms, spheres, true);
  ASSERT_TRUE(fit);
  for (std::size_t h = 0; h < 3; ++h) EXPECT_LT((fit->centres[h] - truths[h]).norm(), 1e-12);
  EXPECT_LT((fit->sphere_centres[0] - ball_centre).norm(), 1e-12);
  EXPECT_NEAR(fit->radii[0], 0.25, 1e-12);
  // Residuals of rounding only: each RMS is its floor, kResolution × the radius.
  for (const double rms : fit->rms) EXPECT_DOUBLE_EQ(rms, detail::kResolution * fit->radii[0]);
}

// δᵀ C⁺ δ over the `rank` largest eigenpairs of a covariance C whose other eigenvalues are zero (a
// fit held by conditions varies only along them), and δ's part outside their span.
std::pair<double, double> chi_square_in_span(const Eigen::MatrixXd& covariance,
                                             const Eigen::VectorXd& error, Eigen::Index rank) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(covariance);
  const Eigen::Index size = covariance.rows();
  const Eigen::MatrixXd span = eigen.eigenvectors().rightCols(rank);
  const Eigen::VectorXd along = span.transpose() * error;
  double chi_square = 0;
  for (Eigen::Index i = 0; i < rank; ++i)
    chi_square += along(i) * along(i) / eigen.eigenvalues()(size - rank + i);
  return {chi_square, (error - span * along).norm()};
}

// A concave fillet of radius 0.2 swept along y, its axis through (x, z) = `centre`: the quarter of
// its circle from `from_degrees` to `to_degrees` (13 points a row, 21 rows), noise 0.002 along its
// normals.
struct Fillet {
  Eigen::Vector2d centre;
  double from_degrees, to_degrees;
  static constexpr double kRadius = 0.2;

  // fit_held_line() of `points` under `holds`, from a start off the truth.
  std::optional<detail::HeldLineFit> fit(const Cluster& points,
                                         std::span<const detail::LineHold> holds = {}) const {
    const detail::CoaxialMember member{points.points, points.weights, kRadius + 0.01};
    return detail::fit_held_line(Eigen::Vector3d::UnitY(),
                                 truth().head<2>() + Eigen::Vector2d(0.01, -0.01), {&member, 1},
                                 holds);
  }
  Cluster draw(std::mt19937_64& rng) const {
    return testing::swept_profile(
        {testing::profile_arc(centre, kRadius, from_degrees, to_degrees, 12)}, 0.002, rng)[0];
  }
  // The fit's parameters y = (line position in orthonormal_pair(y axis) coordinates, radius).
  Eigen::Vector3d truth() const {
    const auto [u, v] = detail::orthonormal_pair(Eigen::Vector3d::UnitY());
    const Eigen::Vector3d axis_point(centre.x(), 0, centre.y());
    return {u.dot(axis_point), v.dot(axis_point), kRadius};
  }
};

TEST(RegularityUncertainty, AFilletsOwnFitAndItsGapToAFaceAreCalibrated) {
  // The fillet between the face z = 0 and a wall, tangent to the face: its own fit (the line and
  // the radius), and its gap to the face as the tangency test weighs it, by that fit's covariance,
  // the face's offset variance and its normal's tilt about the axis times the lever from the
  // face's centroid to the contact. The face is small (8 x 8 points, as noisy as the fillet) and
  // alone in its direction group: its normal is its own fit's, made orthogonal to the axis.
  // Without the offset's variance and the tilt the gap's mean square came out 7.1 deviations²,
  // with the offset's alone 4.3 (and 1.64 without either when the normal is known exactly).
  const Fillet fillet{{0, 0.2}, 180, 270};
  const Eigen::Vector3d direction = Eigen::Vector3d::UnitY(), truth = fillet.truth();
  const auto [u, v] = detail::orthonormal_pair(direction);
  std::mt19937_64 rng(17);
  double fit_sum = 0, gap_sum = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const Cluster points = fillet.draw(rng);
    const Cluster face = noisy_plane(Eigen::Vector3d::UnitZ(), {0.5, 0, 0}, 0.5, 0.002, rng, 8);
    const std::optional<detail::HeldLineFit> fit = fillet.fit(points);
    const std::optional<detail::Oriented> oriented = detail::oriented_plane(1, face.points);
    ASSERT_TRUE(fit && oriented);
    ASSERT_EQ(fit->free, 3u);
    const Eigen::Vector3d error = fit->y - truth;
    fit_sum += error.dot(fit->covariance.inverse() * error);
    Eigen::Vector3d normal = oriented->direction - oriented->direction.dot(direction) * direction;
    normal = (normal.z() < 0 ? -normal : normal).normalized();
    const Eigen::Matrix3d tilt =
        oriented->frame * oriented->covariance * oriented->frame.transpose();
    const std::optional<detail::AlignedPlane> plane =
        detail::aligned_plane(1, normal, face.points, face.weights);
    ASSERT_TRUE(plane);
    // As Tangency::tested_contacts: the axis above the face, so the gap is distance − r.
    const Eigen::Vector2d normal_in_frame(u.dot(normal), v.dot(normal));
    const double distance = normal_in_frame.dot(fit->y.head<2>()) - plane->offset;
    const Eigen::Vector3d row(normal_in_frame.x(), normal_in_frame.y(), -1);
    const Eigen::Vector3d across_axis = direction.cross(normal);
    const double lever =
        Eigen::Vector2d(u.dot(across_axis), v.dot(across_axis)).dot(fit->y.head<2>()) -
        across_axis.dot(plane->centroid);
    gap_sum +=
        std::pow(distance - fit->y(2), 2) / (row.dot(fit->covariance * row) + plane->variance +
                                             lever * lever * across_axis.dot(tilt * across_axis));
  }
  expect_calibrated(fit_sum, 3, "fillet's own line and radius");
  expect_calibrated(gap_sum, 1, "fillet's gap to a small face");
}

TEST(RegularityUncertainty, AFilletsGapToABossIsCalibrated) {
  // A fillet outside a boss of radius 0.5 on the y axis, tangent to it at (x, z) = (0.5, 0): the
  // gap |c − c'| − R − r as the tangency test weighs it, by both cylinders' own fits.
  const Fillet fillet{{0.7, 0}, 180, 270};
  const Eigen::Vector3d direction = Eigen::Vector3d::UnitY();
  std::mt19937_64 rng(20);
  double sum = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const Cluster points = fillet.draw(rng);
    const Cluster boss = noisy_cylinder(direction, Eigen::Vector3d::Zero(), 0.5, 1, 0.002, rng, 8);
    const detail::CoaxialMember held{boss.points, boss.weights, 0.49};
    const std::optional<detail::HeldLineFit> fit = fillet.fit(points);
    const std::optional<detail::HeldLineFit> boss_fit =
        detail::fit_held_line(direction, Eigen::Vector2d(0.01, 0.01), {&held, 1}, {});
    ASSERT_TRUE(fit && boss_fit);
    const Eigen::Vector2d apart = fit->y.head<2>() - boss_fit->y.head<2>();
    const double gap = apart.norm() - boss_fit->y(2) - fit->y(2);
    // As Tangency::tested_contacts: the condition's row in each fit's parameters.
    const Eigen::Vector2d across = apart.normalized();
    const Eigen::Vector3d row(across.x(), across.y(), -1), boss_row(-across.x(), -across.y(), -1);
    sum += gap * gap /
           (row.dot(fit->covariance * row) + boss_row.dot(boss_fit->covariance * boss_row));
  }
  expect_calibrated(sum, 1, "fillet's gap to a boss");
}

// Over kDraws draws of `fillet` (from `seed`) fitted under `hold`, the sum of its errors' χ²
// along the condition (2 degrees of freedom), each fit checked to meet the condition by
// `meets_condition` and its error to leave the fit's span by at most `across`.
template <class MeetsCondition>
double chi_squares_held(const Fillet& fillet, const detail::LineHold& hold, std::uint64_t seed,
                        double across, MeetsCondition meets_condition) {
  std::mt19937_64 rng(seed);
  double sum = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const std::optional<detail::HeldLineFit> fit = fillet.fit(fillet.draw(rng), {&hold, 1});
    if (!fit || fit->free != 2) {
      ADD_FAILURE() << "no fit with 2 free parameters in draw " << draw;
      return 0;
    }
    meets_condition(fit->y);
    const auto [chi_square, off_span] =
        chi_square_in_span(fit->covariance, fit->y - fillet.truth(), 2);
    EXPECT_LT(off_span, across);
    sum += chi_square;
  }
  return sum;
}

TEST(RegularityUncertainty, AFilletHeldTangentToAFaceIsCalibratedAlongIt) {
  const Fillet fillet{{0, 0.2}, 180, 270};
  const auto [u, v] = detail::orthonormal_pair(Eigen::Vector3d::UnitY());
  // n · c − r = 0: the axis at the radius above the face z = 0.
  const detail::LineHold hold{Eigen::Vector3d(u.z(), v.z(), -1), 0, std::nullopt};
  const double sum = chi_squares_held(fillet, hold, 18, 1e-14, [&](const Eigen::VectorXd& y) {
    EXPECT_NEAR(hold.row.dot(y), 0, 1e-14);
  });
  expect_calibrated(sum, 2, "fillet held tangent to a face");
}

TEST(RegularityUncertainty, AFilletHeldTangentToABossIsCalibratedAlongIt) {
  // A boss of radius 0.5 on the y axis and a fillet outside it, tangent at (x, z) = (0.5, 0):
  // |c − 0| = 0.5 + r, a condition linearised again at every step of the fit. The truth is on
  // the curved condition, the fit's span is its tangent at the fit: the error leaves it only by
  // the curvature, (deviation)² / (2 × 0.7).
  const Fillet fillet{{0.7, 0}, 180, 270};
  const detail::LineHold hold{Eigen::Vector3d::Zero(), 0,
                              detail::CircleHold{Eigen::Vector2d::Zero(), 0.5, 1, 1, 2}};
  const double sum = chi_squares_held(fillet, hold, 19, 1e-4, [](const Eigen::VectorXd& y) {
    EXPECT_NEAR(y.head<2>().norm(), 0.5 + y(2), 1e-14);
  });
  expect_calibrated(sum, 2, "fillet held tangent to a boss");
}

}  // namespace
}  // namespace primseg
