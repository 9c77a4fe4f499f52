// The geometric refinement recovers exact primitives from inexact starts, and the reported
// clusters of a cut use it.
#include "primseg/geometric_fit.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <utility>

#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/primitives/torus.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

Eigen::Vector3d eigen(const Vec3& v) {
  return {v[0], v[1], v[2]};
}

// Distance from point p to the line through q along unit a.
double distance_to_line(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                        const Eigen::Vector3d& a) {
  const Eigen::Vector3d d = p - q;
  return (d - a * a.dot(d)).norm();
}

// A random rotation and an origin in [-5, 5]^3.
std::pair<Eigen::Matrix3d, Eigen::Vector3d> random_pose(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0, 1);
  const auto rotation = testing::random_rotation(rng);
  const Eigen::Matrix3d r =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&rotation[0][0]);
  const Eigen::Vector3d origin(10 * unit(rng) - 5, 10 * unit(rng) - 5, 10 * unit(rng) - 5);
  return {r, origin};
}

// Cylinders sampled on a grid whose vertices are jittered along the surface (so they lie on it
// exactly, but the triangles are irregular and the algebraic fit is only approximate), at random
// poses and scales: the reported primitive is the cylinder to 1e-9.
TEST(GeometricFit, RecoversJitteredExactCylindersToOneInABillion) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), unit(0, 1);
  double worst_algebraic = 0;
  for (int trial = 0; trial < 8; ++trial) {
    const double radius = 0.5 + unit(rng), height = 1 + 2 * unit(rng), turn = 0.4 + 0.5 * unit(rng);
    const int rows = 12, cols = 24;
    Mesh mesh = testing::grid_mesh(rows, cols, [&](double u, double v) {
      const double interior_u = (u > 0 && u < 1) ? jitter(rng) / rows : 0;
      const double interior_v = (v > 0 && v < 1) ? jitter(rng) / cols : 0;
      const double angle = 2 * M_PI * turn * (v + interior_v), z = height * (u + interior_u);
      return Vec3{radius * std::cos(angle), radius * std::sin(angle), z};
    });
    const auto rotation = testing::random_rotation(rng);
    const double scale = std::exp2(8 * unit(rng) - 4);
    const Vec3 translation{10 * unit(rng) - 5, 10 * unit(rng) - 5, 10 * unit(rng) - 5};
    testing::transform(mesh, rotation, scale, translation);
    const Eigen::Vector3d axis(rotation[0][2], rotation[1][2], rotation[2][2]);
    const Eigen::Vector3d on_axis = eigen(translation);

    const Hierarchy h = build_hierarchy(mesh);
    const std::vector<ClusterReport> reports = describe_clusters(h, cut_by_count(h, 1));
    ASSERT_EQ(reports.size(), 1u);
    const Primitive& p = reports[0].primitive;
    ASSERT_EQ(p.type, PrimitiveType::Cylinder) << "trial " << trial;
    EXPECT_NEAR(p.radius, radius * scale, 1e-9 * radius * scale) << "trial " << trial;
    EXPECT_NEAR(std::abs(eigen(p.axis).dot(axis)), 1.0, 1e-12) << "trial " << trial;
    EXPECT_LE(eigen(p.axis).cross(axis).norm(), 1e-9) << "trial " << trial;
    EXPECT_LE(distance_to_line(eigen(p.point), on_axis, axis), 1e-9 * scale) << "trial " << trial;
    EXPECT_LE(reports[0].rms, 1e-9 * scale);
    EXPECT_LE(reports[0].max, 1e-9 * scale);
    worst_algebraic =
        std::max(worst_algebraic, std::abs(reports[0].algebraic.radius / (radius * scale) - 1));
  }
  // The algebraic starts were measurably off: the refinement did the work.
  EXPECT_GT(worst_algebraic, 1e-7);
}

TEST(GeometricFit, RecoversASphereFromAPerturbedStart) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  const Eigen::Vector3d centre(1e3, -2e3, 5e2);
  const double radius = 0.25;
  std::vector<Vec3> points;
  std::vector<double> weights;
  for (int i = 0; i < 200; ++i) {
    // A cap of the sphere only (z > 0.5 r): the harder, less symmetric case.
    Eigen::Vector3d d(normal(rng), normal(rng), std::abs(normal(rng)) + 1.0);
    const Eigen::Vector3d x = centre + radius * d.normalized();
    points.push_back({x.x(), x.y(), x.z()});
    weights.push_back(1 + i % 3);
  }
  Primitive start;
  start.type = PrimitiveType::Sphere;
  start.point = {centre.x() + 0.01, centre.y() - 0.02, centre.z() + 0.01};
  start.radius = 0.27;
  const GeometricFit fit = fit_geometric(start, points, weights);
  EXPECT_LE((eigen(fit.primitive.point) - centre).norm(), 1e-9 * radius);
  EXPECT_NEAR(fit.primitive.radius, radius, 1e-9 * radius);
  EXPECT_LE(fit.max, 1e-9 * radius);
  EXPECT_GT(fit.iterations, 0);
}

TEST(GeometricFit, PlaneOfNoisyPointsIsTheLeastSquaresPlane) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  std::vector<Vec3> points;
  std::vector<double> weights(500, 1.0);
  for (int i = 0; i < 500; ++i) points.push_back({normal(rng), normal(rng), 0.01 * normal(rng)});
  Primitive start;
  start.type = PrimitiveType::Plane;
  start.point = {0.1, 0, 0.05};
  start.axis = {0.1, 0, 1};
  const GeometricFit fit = fit_geometric(start, points, weights);
  // The least-squares plane: through the centroid, normal the smallest principal direction.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Vec3& p : points) mean += eigen(p) / 500.0;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Vec3& p : points) covariance += (eigen(p) - mean) * (eigen(p) - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Eigen::Vector3d expected = solver.eigenvectors().col(0);
  EXPECT_NEAR(std::abs(eigen(fit.primitive.axis).dot(expected)), 1.0, 1e-12);
  EXPECT_GT(eigen(fit.primitive.axis).z(), 0) << "keeps the side of the start";
  EXPECT_NEAR(std::abs((eigen(fit.primitive.point) - mean).dot(expected)), 0.0, 1e-12);
  EXPECT_NEAR(fit.rms, std::sqrt(solver.eigenvalues()[0] / 500.0), 1e-12);
}

// Points exactly on a cone or torus at a random pose, a start off by a few percent: the
// refinement lands on the surface to round-off.
TEST(GeometricFit, RecoversConesAndToriFromPerturbedStarts) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int trial = 0; trial < 10; ++trial) {
    const auto [r, origin] = random_pose(rng);
    const Eigen::Vector3d axis = r.col(2);
    const double half_angle = 0.2 + unit(rng), major = 1 + unit(rng), minor = 0.2 + 0.5 * unit(rng);
    std::vector<Vec3> cone_points, torus_points;
    for (int i = 0; i < 300; ++i) {
      const double phi = 2 * unit(rng), t = 0.5 + unit(rng), psi = 3 * unit(rng) - 1.5;
      const Eigen::Vector3d radial = r * Eigen::Vector3d(std::cos(phi), std::sin(phi), 0);
      const Eigen::Vector3d c =
          origin + t * (std::cos(half_angle) * axis + std::sin(half_angle) * radial);
      const Eigen::Vector3d x =
          origin + (major + minor * std::cos(psi)) * radial + minor * std::sin(psi) * axis;
      cone_points.push_back({c.x(), c.y(), c.z()});
      torus_points.push_back({x.x(), x.y(), x.z()});
    }
    const std::vector<double> weights(300, 1.0);
    const Eigen::Vector3d tilted = (axis + Eigen::Vector3d(0.03, -0.02, 0.01)).normalized();
    const Eigen::Vector3d moved = origin + Eigen::Vector3d(0.02, 0.01, -0.03);

    Primitive cone;
    cone.type = PrimitiveType::Cone;
    cone.point = {moved.x(), moved.y(), moved.z()};
    cone.axis = {tilted.x(), tilted.y(), tilted.z()};
    cone.half_angle = half_angle * 1.05;
    const GeometricFit cone_fit = fit_geometric(cone, cone_points, weights);
    EXPECT_LE((eigen(cone_fit.primitive.point) - origin).norm(), 1e-9) << trial;
    EXPECT_GT(eigen(cone_fit.primitive.axis).dot(axis), 1 - 1e-12) << trial;
    EXPECT_NEAR(cone_fit.primitive.half_angle, half_angle, 1e-9) << trial;
    EXPECT_LE(cone_fit.max, 1e-9) << trial;

    Primitive torus;
    torus.type = PrimitiveType::Torus;
    torus.point = {moved.x(), moved.y(), moved.z()};
    torus.axis = {tilted.x(), tilted.y(), tilted.z()};
    torus.radius = major * 1.03;
    torus.minor_radius = minor * 0.95;
    const GeometricFit torus_fit = fit_geometric(torus, torus_points, weights);
    EXPECT_LE((eigen(torus_fit.primitive.point) - origin).norm(), 1e-9) << trial;
    EXPECT_NEAR(std::abs(eigen(torus_fit.primitive.axis).dot(axis)), 1, 1e-12) << trial;
    EXPECT_NEAR(torus_fit.primitive.radius, major, 1e-9) << trial;
    EXPECT_NEAR(torus_fit.primitive.minor_radius, minor, 1e-9) << trial;
    EXPECT_LE(torus_fit.max, 1e-9) << trial;
  }
  for (int t = 0; t < kPrimitiveTypeCount; ++t)
    EXPECT_TRUE(has_geometric_model(static_cast<PrimitiveType>(t)));
}

// A torus whose fit shrinks its ring to a point is the sphere of its tube: fit_geometric_or_sphere
// returns that sphere (what reports and the denoiser show), and a true torus as fit_geometric does.
TEST(GeometricFit, ATorusWhoseRingVanishesIsFittedAsTheSphereOfItsTube) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  const Eigen::Vector3d centre(2, -1, 0.5);
  const double radius = 0.4;
  std::vector<Vec3> sphere_points;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d x =
        centre + radius * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    sphere_points.push_back({x.x(), x.y(), x.z()});
  }
  const std::vector<double> weights(sphere_points.size(), 1.0);
  Primitive torus;
  torus.type = PrimitiveType::Torus;
  torus.point = {centre.x() + 0.01, centre.y(), centre.z() - 0.01};
  torus.axis = {0, 0, 1};
  torus.radius = 0.06 * radius;
  torus.minor_radius = 0.95 * radius;
  ASSERT_TRUE(torus_ring_vanishes(fit_geometric(torus, sphere_points, weights).primitive))
      << "the torus's own fit must shrink its ring for this test to mean anything";
  const GeometricFit fit = fit_geometric_or_sphere(torus, sphere_points, weights);
  EXPECT_EQ(fit.primitive.type, PrimitiveType::Sphere);
  EXPECT_NEAR(fit.primitive.radius, radius, 1e-9 * radius);
  EXPECT_LE((eigen(fit.primitive.point) - centre).norm(), 1e-9 * radius);
  EXPECT_LE(fit.max, 1e-9 * radius);

  // A torus whose ring stays is fit_geometric's torus, bit for bit.
  std::vector<Vec3> torus_points;
  for (int i = 0; i < 300; ++i) {
    const double phi = 0.02 * i, psi = 0.05 * i;
    torus_points.push_back({(1 + 0.3 * std::cos(psi)) * std::cos(phi),
                            (1 + 0.3 * std::cos(psi)) * std::sin(phi), 0.3 * std::sin(psi)});
  }
  torus.point = {0.01, -0.02, 0};
  torus.radius = 1.05;
  torus.minor_radius = 0.28;
  const GeometricFit kept = fit_geometric_or_sphere(torus, torus_points, weights);
  const GeometricFit plain = fit_geometric(torus, torus_points, weights);
  EXPECT_EQ(kept.primitive.type, PrimitiveType::Torus);
  EXPECT_EQ(kept.primitive.point, plain.primitive.point);
  EXPECT_EQ(kept.primitive.radius, plain.primitive.radius);
  EXPECT_EQ(kept.rms, plain.rms);
  EXPECT_NEAR(kept.primitive.radius, 1, 1e-9);
}

// Noisy points have no exact fit: the refinement must still reach the least-squares minimum,
// where Σ w d² is stationary in every parameter, not merely stop lowering it. For a sphere
// (centre c, radius r, unit directions n = (x − c)/|x − c|): Σ w d = 0 and Σ w d n = 0. For a
// cylinder (axis a through q, n the unit radial direction, t = a·(x − q) the axial coordinate):
// Σ w d = 0, Σ w d n = 0 and Σ w d t n = 0 (tilting the axis). Each sum is compared with the
// same sum of |d|. The fit stops once a step would lower Σ w d² by at most 1e-15 of it, which
// leaves these ratios near 1e-8 (the square root); a fit stopped at 1e-10 leaves them near 1e-5.
// A second fit from the result makes at most one more step.
TEST(GeometricFit, NoisyFitsReachTheLeastSquaresMinimum) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> noise(0, 0.01);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int trial = 0; trial < 6; ++trial) {
    const auto [r, origin] = random_pose(rng);
    const double radius = 0.5 + unit(rng);
    std::vector<Vec3> sphere_points, cylinder_points;
    std::vector<double> weights;
    for (int i = 0; i < 400; ++i) {
      // A cap and a partial cylinder: an unevenly constrained fit.
      const double phi = 2.5 * unit(rng), z = 0.2 + 0.8 * unit(rng);
      const Eigen::Vector3d cap(std::sqrt(1 - z * z) * std::cos(phi),
                                std::sqrt(1 - z * z) * std::sin(phi), z);
      const Eigen::Vector3d s = origin + (radius + noise(rng)) * (r * cap);
      const Eigen::Vector3d c =
          origin + r * Eigen::Vector3d((radius + noise(rng)) * std::cos(phi),
                                       (radius + noise(rng)) * std::sin(phi), 3 * z);
      sphere_points.push_back({s.x(), s.y(), s.z()});
      cylinder_points.push_back({c.x(), c.y(), c.z()});
      weights.push_back(0.5 + unit(rng));
    }
    const Eigen::Vector3d axis = r.col(2);
    const Eigen::Vector3d moved = origin + Eigen::Vector3d(0.03, -0.02, 0.02);
    const Eigen::Vector3d tilted = (axis + Eigen::Vector3d(0.02, 0.03, -0.01)).normalized();

    Primitive sphere;
    sphere.type = PrimitiveType::Sphere;
    sphere.point = {moved.x(), moved.y(), moved.z()};
    sphere.radius = radius * 1.05;
    const GeometricFit sphere_fit = fit_geometric(sphere, sphere_points, weights);
    {
      const Eigen::Vector3d centre = eigen(sphere_fit.primitive.point);
      double sum_d = 0, sum_abs = 0;
      Eigen::Vector3d sum_dn = Eigen::Vector3d::Zero();
      for (std::size_t i = 0; i < sphere_points.size(); ++i) {
        const Eigen::Vector3d offset = eigen(sphere_points[i]) - centre;
        const double d = offset.norm() - sphere_fit.primitive.radius;
        sum_d += weights[i] * d;
        sum_dn += weights[i] * d * offset.normalized();
        sum_abs += weights[i] * std::abs(d);
      }
      EXPECT_GT(sphere_fit.rms, 0.005) << "the points are noisy";
      EXPECT_LE(std::abs(sum_d), 1e-7 * sum_abs) << trial;
      EXPECT_LE(sum_dn.norm(), 1e-7 * sum_abs) << trial;
      const GeometricFit again = fit_geometric(sphere_fit.primitive, sphere_points, weights);
      EXPECT_LE(again.iterations, 1) << trial;
      EXPECT_NEAR(again.rms, sphere_fit.rms, 1e-12 * sphere_fit.rms) << trial;
    }

    Primitive cylinder;
    cylinder.type = PrimitiveType::Cylinder;
    cylinder.point = {moved.x(), moved.y(), moved.z()};
    cylinder.axis = {tilted.x(), tilted.y(), tilted.z()};
    cylinder.radius = radius * 0.95;
    const GeometricFit cylinder_fit = fit_geometric(cylinder, cylinder_points, weights);
    {
      const Eigen::Vector3d a = eigen(cylinder_fit.primitive.axis).normalized();
      const Eigen::Vector3d q = eigen(cylinder_fit.primitive.point);
      double sum_d = 0, sum_abs = 0, sum_abs_t = 0;
      Eigen::Vector3d sum_dn = Eigen::Vector3d::Zero(), sum_dtn = Eigen::Vector3d::Zero();
      for (std::size_t i = 0; i < cylinder_points.size(); ++i) {
        const Eigen::Vector3d offset = eigen(cylinder_points[i]) - q;
        const double t = a.dot(offset);
        const Eigen::Vector3d radial = offset - t * a;
        const double d = radial.norm() - cylinder_fit.primitive.radius;
        sum_d += weights[i] * d;
        sum_dn += weights[i] * d * radial.normalized();
        sum_dtn += weights[i] * d * t * radial.normalized();
        sum_abs += weights[i] * std::abs(d);
        sum_abs_t += weights[i] * std::abs(d * t);
      }
      EXPECT_GT(cylinder_fit.rms, 0.005) << "the points are noisy";
      EXPECT_GT(std::abs(a.dot(axis)), 0.999) << trial;
      EXPECT_LE(std::abs(sum_d), 1e-7 * sum_abs) << trial;
      EXPECT_LE(sum_dn.norm(), 1e-7 * sum_abs) << trial;
      EXPECT_LE(sum_dtn.norm(), 1e-7 * sum_abs_t) << trial;
      const GeometricFit again = fit_geometric(cylinder_fit.primitive, cylinder_points, weights);
      EXPECT_LE(again.iterations, 1) << trial;
      EXPECT_NEAR(again.rms, cylinder_fit.rms, 1e-12 * cylinder_fit.rms) << trial;
    }
  }
}

// A start far beyond the points' own size: points with subnormal coordinates (a tree file's
// cluster, found by the tree fuzzer) and a plane 2 units away. Measured in a frame scaled to the
// points alone, the plane's distance overflowed and the RMS came out NaN.
TEST(GeometricFit, AStartFarBeyondThePointsSizeKeepsDistancesFinite) {
  Primitive plane;
  plane.point = {2, 0, 0};
  plane.axis = {1, 0, 0};
  const std::vector<Vec3> points{
      {1e-311, 0, 0}, {0, 3e-311, 0}, {0, 0, 2e-311}, {1e-311, 1e-311, 0}};
  const std::vector<double> weights(points.size(), 1.0);
  GeometricFitOptions stay;
  stay.max_iterations = 0;
  const GeometricFit at_start = fit_geometric(plane, points, weights, stay);
  EXPECT_DOUBLE_EQ(at_start.rms, 2);
  EXPECT_DOUBLE_EQ(at_start.max, 2);
  const GeometricFit fitted = fit_geometric(plane, points, weights);
  EXPECT_TRUE(std::isfinite(fitted.rms));
  EXPECT_LE(fitted.rms, 1e-310);
  EXPECT_LE(fitted.max, 1e-310);
}

TEST(GeometricFit, RejectsBadInput) {
  Primitive plane;
  plane.axis = {0, 0, 1};
  const std::vector<Vec3> points{{0, 0, 0}, {1, 0, 0}};
  const std::vector<double> one{1}, negative{1, -1};
  EXPECT_THROW(fit_geometric(plane, points, one), InvalidInputError);
  EXPECT_THROW(fit_geometric(plane, points, negative), InvalidInputError);
}

}  // namespace
}  // namespace primseg
