// Fitters recover analytic primitives from sampled triangulations at random poses and scales.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "primseg/dual_graph.hpp"
#include "primseg/primitives/cylinder.hpp"
#include "primseg/primitives/plane.hpp"
#include "primseg/primitives/sphere.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using testing::grid_mesh;
using testing::whole_mesh_stats;

struct Pose {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  double scale;
  Vec3 apply(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d y = scale * (rotation * x) + translation;
    return {y.x(), y.y(), y.z()};
  }
};

Pose random_pose(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1, 1);
  Pose pose;
  const auto r = testing::random_rotation(rng);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) pose.rotation(i, j) = r[i][j];
  pose.scale = std::pow(10.0, 3 * unit(rng));
  pose.translation = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * 5 * pose.scale;
  return pose;
}

// Fits in the working frame, reports in input units.
PrimitiveFit fit_whole(const Mesh& mesh, const PrimitiveFitter& fitter, Primitive* input) {
  const DualGraph graph(mesh, VertexWeights::Area);
  PrimitiveFit fit = fitter.fit(whole_mesh_stats(graph));
  *input = graph.frame().to_input(fit.primitive);
  return fit;
}

double angle_between_axes(const Vec3& a, const Eigen::Vector3d& b) {
  // atan2 of |u × v| and |u · v|: acos near 1 only resolves about 1.5e-8 rad.
  const Eigen::Vector3d u = Eigen::Vector3d(a[0], a[1], a[2]).normalized();
  return std::atan2(u.cross(b.normalized()).norm(), std::abs(u.dot(b.normalized())));
}

double distance(const Vec3& a, const Vec3& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

TEST(PlaneFitter, RecoversPlanesAtRandomPosesAndScales) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const Pose pose = random_pose(rng);
    const Mesh mesh = grid_mesh(5, 7, [&](double u, double v) {
      return pose.apply({2 * u - 0.3, 1.5 * v + 0.2 * u, 0.0});
    });
    Primitive plane;
    const PrimitiveFit fit = fit_whole(mesh, PlaneFitter(), &plane);
    ASSERT_TRUE(fit.valid);
    const Eigen::Vector3d normal = pose.rotation.col(2);
    EXPECT_LT(angle_between_axes(plane.axis, normal), 1e-9);
    // Oriented along the face normals (the grid's (∂u × ∂v) is +z before the pose).
    EXPECT_GT(Eigen::Vector3d(plane.axis[0], plane.axis[1], plane.axis[2]).dot(normal), 0);
    for (const Vec3& p : mesh.positions) EXPECT_LT(plane.distance(p), 1e-9 * pose.scale);
    // Round-off only: far below the engine's zero-snap level (1e-12 of the spread).
    const DualGraph graph(mesh, VertexWeights::Area);
    EXPECT_LT(fit.error, 1e-14 * whole_mesh_stats(graph).moments.second_moment().trace());
  }
}

TEST(SphereFitter, RecoversSpheresAtRandomPosesAndScales) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const Pose pose = random_pose(rng);
    const double radius = 0.5 + trial * 0.05;
    // A cap of modest extent: the hard case for algebraic fits.
    const Mesh mesh = grid_mesh(6, 8, [&](double u, double v) {
      const double theta = 0.4 + 0.5 * u, phi = 1.2 * v;
      return pose.apply(radius * Eigen::Vector3d(std::sin(theta) * std::cos(phi),
                                                 std::sin(theta) * std::sin(phi), std::cos(theta)));
    });
    Primitive sphere;
    const PrimitiveFit fit = fit_whole(mesh, SphereFitter(), &sphere);
    ASSERT_TRUE(fit.valid);
    const double r = radius * pose.scale;
    EXPECT_NEAR(sphere.radius, r, 1e-9 * r);
    EXPECT_LT(distance(sphere.point, pose.apply(Eigen::Vector3d::Zero())), 1e-9 * r);
  }
}

TEST(CylinderFitter, RecoversRingByGeneratorCylindersExactly) {
  std::mt19937_64 rng(13);
  for (int trial = 0; trial < 50; ++trial) {
    const Pose pose = random_pose(rng);
    const double radius = 0.3 + 0.04 * trial;
    const Mesh mesh = grid_mesh(4, 12, [&](double u, double v) {
      const double phi = 2.0 * v;  // a third of the way around
      return pose.apply(Eigen::Vector3d(radius * std::cos(phi), radius * std::sin(phi), 1.5 * u));
    });
    Primitive cylinder;
    const PrimitiveFit fit = fit_whole(mesh, CylinderFitter(), &cylinder);
    ASSERT_TRUE(fit.valid);
    const double r = radius * pose.scale;
    EXPECT_NEAR(cylinder.radius, r, 1e-9 * r);
    EXPECT_LT(angle_between_axes(cylinder.axis, pose.rotation.col(2)), 1e-9);
    for (const Vec3& p : mesh.positions) EXPECT_LT(cylinder.distance(p), 1e-9 * r);
    // Canonical form: axis with its largest-magnitude component positive, point = the centroid
    // of the vertices' weights projected on the axis (on the axis, at the patch's middle height).
    const Eigen::Vector3d axis(cylinder.axis[0], cylinder.axis[1], cylinder.axis[2]);
    Eigen::Index largest;
    axis.cwiseAbs().maxCoeff(&largest);
    EXPECT_GT(axis(largest), 0);
    const Vec3 middle = pose.apply(Eigen::Vector3d(0, 0, 0.75));
    EXPECT_LT(distance(cylinder.point, middle), 1e-9 * r);
  }
}

TEST(CylinderFitter, AxisOfAJitteredTessellationWithinAMilliradian) {
  std::mt19937_64 rng(17);
  // Every vertex moves by up to a quarter of the grid step along and around the axis. (The tensor
  // axis degrades past about a third of a step, where neighbouring rings nearly touch.)
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pose = random_pose(rng);
    // Vertices stay exactly on the cylinder but the rings are irregular.
    std::vector<double> offsets(13 * 7);
    for (double& o : offsets) o = jitter(rng);
    const Mesh mesh = grid_mesh(
        6, 12,
        [&](double u, double v) {
          const int i = static_cast<int>(std::lround(u * 6)),
                    j = static_cast<int>(std::lround(v * 12));
          const double phi = (j + offsets[i * 13 + j] * (j > 0 && j < 12)) * 0.2;
          const double z = (i + offsets[i * 13 + j] * (i > 0 && i < 6)) * 0.25;
          return pose.apply(Eigen::Vector3d(std::cos(phi), std::sin(phi), z));
        },
        true);
    Primitive cylinder;
    const PrimitiveFit fit = fit_whole(mesh, CylinderFitter(), &cylinder);
    ASSERT_TRUE(fit.valid);
    EXPECT_LT(angle_between_axes(cylinder.axis, pose.rotation.col(2)), 1e-3);
  }
}

TEST(CylinderFitter, AxisWithinTwoDegreesUnderOnePercentNoise) {
  // The paper's Figure 3 claim: the tensor axis survives noise where the Gauss image does not.
  std::mt19937_64 rng(19);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pose = random_pose(rng);
    const Mesh mesh = grid_mesh(20, 30, [&](double u, double v) {
      const double phi = 3.0 * v, rho = 1.0 + noise(rng);
      return pose.apply(Eigen::Vector3d(rho * std::cos(phi), rho * std::sin(phi), 3.0 * u));
    });
    Primitive cylinder;
    const PrimitiveFit fit = fit_whole(mesh, CylinderFitter(), &cylinder);
    ASSERT_TRUE(fit.valid);
    EXPECT_LT(angle_between_axes(cylinder.axis, pose.rotation.col(2)), 2 * M_PI / 180);
    EXPECT_NEAR(cylinder.radius, pose.scale, 0.02 * pose.scale);
  }
}

TEST(Fitters, DegenerateClustersNeverYieldNonFiniteOrWinningCurvedFits) {
  // One triangle, a collinear sliver, and a flat patch given to the curved fitters.
  const Mesh triangle =
      Mesh::from_triangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {Triangle{0, 1, 2}});
  const Mesh sliver = Mesh::from_triangles({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {Triangle{0, 1, 2}});
  const Mesh flat = grid_mesh(6, 6, [](double u, double v) { return Vec3{u, v, 0}; });
  for (const Mesh* mesh : {&triangle, &sliver, &flat}) {
    Primitive p;
    const PrimitiveFit plane = fit_whole(*mesh, PlaneFitter(), &p);
    EXPECT_TRUE(plane.valid);
    EXPECT_TRUE(std::isfinite(plane.error));
    for (double c : p.axis) EXPECT_TRUE(std::isfinite(c));
    EXPECT_FALSE(fit_whole(*mesh, SphereFitter(), &p).valid);
    EXPECT_FALSE(fit_whole(*mesh, CylinderFitter(), &p).valid);
  }
}

TEST(Fitters, SlightlyNoisyFlatPatchDoesNotBecomeAHugeSphere) {
  std::mt19937_64 rng(23);
  std::normal_distribution<double> noise(0.0, 1e-9);
  const Mesh flat = grid_mesh(10, 10, [&](double u, double v) { return Vec3{u, v, noise(rng)}; });
  Primitive p;
  const PrimitiveFit sphere = fit_whole(flat, SphereFitter(), &p);
  EXPECT_FALSE(sphere.valid) << "radius " << p.radius;
}

}  // namespace
}  // namespace primseg
