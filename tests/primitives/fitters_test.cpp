// Fitters recover analytic primitives from sampled triangulations at random poses and scales.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>

#include "primseg/cluster_view.hpp"
#include "primseg/dual_graph.hpp"
#include "primseg/primitives/cone.hpp"
#include "primseg/primitives/cylinder.hpp"
#include "primseg/primitives/plane.hpp"
#include "primseg/primitives/sphere.hpp"
#include "primseg/primitives/torus.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using testing::grid_mesh;
using testing::part_stats;
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

// `mesh` and a flat cap over an arc: a fan of triangles from the first of the arc's points
// arc_point(j / 24), j = 0..24, with no vertex inside (a CAD-style flat face).
template <typename ArcPoint>
Mesh with_fan_cap(const Mesh& mesh, ArcPoint&& arc_point) {
  std::vector<Vec3> positions = mesh.positions;
  std::vector<Triangle> triangles = mesh.triangles;
  const auto first = static_cast<std::uint32_t>(positions.size());
  const int arc = 24;
  for (int j = 0; j <= arc; ++j) positions.push_back(arc_point(double(j) / arc));
  for (std::uint32_t j = 1; j < arc; ++j) triangles.push_back({first, first + j, first + j + 1});
  return Mesh::from_triangles(std::move(positions), std::move(triangles));
}

using testing::distance;

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

// A band of a cone (apex at the origin, axis +z, half-angle θ) between distances t0 and t1 from
// the apex along the generators, over `turn` radians, triangulated ring by generator.
Eigen::Vector3d cone_point(double half_angle, double t, double phi) {
  return t * Eigen::Vector3d(std::sin(half_angle) * std::cos(phi),
                             std::sin(half_angle) * std::sin(phi), std::cos(half_angle));
}

TEST(ConeFitter, RecoversRingByGeneratorConesExactly) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const Pose pose = random_pose(rng);
    const double half_angle = 0.1 + 1.3 * unit(rng);  // 6 to 80 degrees
    const double t0 = 0.2 + unit(rng), t1 = t0 + 0.5 + unit(rng);
    const double turn = 1.5 + 4.5 * unit(rng);
    // Inside of the cone (a countersink) on odd trials: the faces turn to the axis.
    const bool hole = trial % 2;
    const Mesh mesh = grid_mesh(4, 16, [&](double u, double v) {
      return pose.apply(cone_point(half_angle, t0 + (t1 - t0) * u, (hole ? -turn : turn) * v));
    });
    Primitive cone;
    const PrimitiveFit fit = fit_whole(mesh, ConeFitter(), &cone);
    ASSERT_TRUE(fit.valid) << trial;
    EXPECT_EQ(cone.type, PrimitiveType::Cone);
    const Vec3 apex = pose.apply(Eigen::Vector3d::Zero());
    EXPECT_LT(distance(cone.point, apex), 1e-6 * pose.scale) << trial;
    const Eigen::Vector3d axis(cone.axis[0], cone.axis[1], cone.axis[2]);
    // From the apex into the cone.
    EXPECT_GT(axis.dot(pose.rotation.col(2)), 1 - 1e-6) << trial;
    EXPECT_NEAR(cone.half_angle, half_angle, 1e-6) << trial;
    for (const Vec3& p : mesh.positions) EXPECT_LT(cone.distance(p), 1e-6 * pose.scale);
    const DualGraph graph(mesh, VertexWeights::Area);
    EXPECT_LT(fit.error, 1e-12 * whole_mesh_stats(graph).moments.second_moment().trace());
  }
}

TEST(ConeFitter, PointedConeWithItsApexInTheCluster) {
  std::mt19937_64 rng(31);
  for (int trial = 0; trial < 10; ++trial) {
    const Pose pose = random_pose(rng);
    const double half_angle = 0.3 + 0.1 * trial;
    // A fan of triangles around the apex, closed all the way round, and two rings below it.
    const Mesh mesh = grid_mesh(3, 24, [&](double u, double v) {
      return pose.apply(cone_point(half_angle, 1e-3 + u, 2 * M_PI * v));
    });
    Primitive cone;
    const PrimitiveFit fit = fit_whole(mesh, ConeFitter(), &cone);
    ASSERT_TRUE(fit.valid) << trial;
    EXPECT_LT(distance(cone.point, pose.apply(Eigen::Vector3d::Zero())), 1e-6 * pose.scale);
    EXPECT_NEAR(cone.half_angle, half_angle, 1e-6);
  }
}

TEST(ConeFitter, JitteredVerticesOnTheConeAndNoiseAlongTheNormals) {
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);
  std::normal_distribution<double> noise(0.0, 0.002);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pose = random_pose(rng);
    const double half_angle = M_PI / 4;
    // Irregular rings (every vertex still on the cone, so face planes miss the apex slightly),
    // then the same with Gaussian noise of 0.2% of the size along the normals.
    for (const bool noisy : {false, true}) {
      std::vector<double> offsets(21 * 41);
      for (double& o : offsets) o = jitter(rng);
      const Mesh mesh = grid_mesh(20, 40, [&](double u, double v) {
        const int i = static_cast<int>(std::lround(u * 20)),
                  j = static_cast<int>(std::lround(v * 40));
        const double o = offsets[i * 41 + j];
        const double t = 0.5 + (i + o * (i > 0 && i < 20)) / 20.0;
        const double phi = 3.0 * (j + o * (j > 0 && j < 40)) / 40.0;
        const Eigen::Vector3d normal(std::cos(half_angle) * std::cos(phi),
                                     std::cos(half_angle) * std::sin(phi), -std::sin(half_angle));
        return pose.apply(cone_point(half_angle, t, phi) + (noisy ? noise(rng) : 0.0) * normal);
      });
      Primitive cone;
      const PrimitiveFit fit = fit_whole(mesh, ConeFitter(), &cone);
      ASSERT_TRUE(fit.valid) << trial << noisy;
      const double tolerance = noisy ? 0.02 : 2e-3;
      EXPECT_LT(distance(cone.point, pose.apply(Eigen::Vector3d::Zero())), tolerance * pose.scale)
          << trial << noisy;
      EXPECT_LT(angle_between_axes(cone.axis, pose.rotation.col(2)), tolerance) << trial << noisy;
      EXPECT_NEAR(cone.half_angle, half_angle, tolerance) << trial << noisy;
      // The error is an honest L2: close to the exact Σ w d² of the reported cone.
      if (noisy) {
        const DualGraph graph(mesh, VertexWeights::Area);
        double exact = 0;
        for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
          const Triangle corners = graph.corners(t);
          const auto w = graph.corner_weights(t);
          for (int c = 0; c < 3; ++c) {
            const Eigen::Vector3d& x = graph.position(corners[c]);
            exact += w[c] * std::pow(fit.primitive.distance({x.x(), x.y(), x.z()}), 2);
          }
        }
        EXPECT_NEAR(fit.error, exact, 0.2 * exact) << trial;
      }
    }
  }
}

TEST(ConeFitter, NearlyCylindricalOrFlatConesAreNotCones) {
  // Below kMinConeHalfAngle a cone is the cylinder it nearly is; near 90° the plane.
  for (const double degrees : {1.0, 89.0}) {
    const double half_angle = degrees * M_PI / 180;
    const Mesh mesh = grid_mesh(4, 16, [&](double u, double v) {
      const Eigen::Vector3d p = cone_point(half_angle, 1 + u, 2.0 * v);
      return Vec3{p.x(), p.y(), p.z()};
    });
    Primitive cone;
    EXPECT_FALSE(fit_whole(mesh, ConeFitter(), &cone).valid) << degrees;
  }
  // A cylinder and a sphere cap.
  const Mesh cylinder = grid_mesh(4, 12, [](double u, double v) {
    return Vec3{std::cos(2 * v), std::sin(2 * v), 1.5 * u};
  });
  Primitive p;
  EXPECT_FALSE(fit_whole(cylinder, ConeFitter(), &p).valid);
}

TEST(ConeFitter, PointsOnBothNappesAreNotACone) {
  // Two opposite bands of the double cone x² + y² = z²: the quadric fits them, one cone does not.
  const Mesh mesh = grid_mesh(8, 16, [](double u, double v) {
    const double t = -1.5 + 3 * u + (u > 0.49 && u < 0.51 ? 0.01 : 0);
    const Eigen::Vector3d p = cone_point(M_PI / 4, t, 2.0 * v);
    return Vec3{p.x(), p.y(), p.z()};
  });
  Primitive p;
  EXPECT_FALSE(fit_whole(mesh, ConeFitter(), &p).valid);
}

// A patch of the torus of centre 0, axis +z, radii R and r: tube angle ψ (0 on the outer
// equator), angle φ around the axis.
Eigen::Vector3d torus_point(double major, double minor, double psi, double phi) {
  const double rho = major + minor * std::cos(psi);
  return {rho * std::cos(phi), rho * std::sin(phi), minor * std::sin(psi)};
}

TEST(TorusFitter, RecoversTorusPatchesAtRandomPosesAndScales) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const Pose pose = random_pose(rng);
    const double major = 0.5 + unit(rng), minor = (0.1 + 0.8 * unit(rng)) * major;
    // From a quarter of the tube (a fillet) to most of it, a third of the way round or more.
    const double psi0 = -1.5 * unit(rng), psi1 = psi0 + M_PI / 2 + 2 * unit(rng);
    const double turn = 2 + 4 * unit(rng);
    const Mesh mesh = grid_mesh(8, 24, [&](double u, double v) {
      return pose.apply(torus_point(major, minor, psi0 + (psi1 - psi0) * u, turn * v));
    });
    Primitive torus;
    const PrimitiveFit fit = fit_whole(mesh, TorusFitter(), &torus);
    ASSERT_TRUE(fit.valid) << trial;
    EXPECT_EQ(torus.type, PrimitiveType::Torus);
    const double s = pose.scale;
    EXPECT_LT(distance(torus.point, pose.apply(Eigen::Vector3d::Zero())), 1e-6 * s) << trial;
    EXPECT_LT(angle_between_axes(torus.axis, pose.rotation.col(2)), 1e-6) << trial;
    EXPECT_NEAR(torus.radius, major * s, 1e-6 * s) << trial;
    EXPECT_NEAR(torus.minor_radius, minor * s, 1e-6 * s) << trial;
    for (const Vec3& p : mesh.positions) EXPECT_LT(torus.distance(p), 1e-6 * s);
    const DualGraph graph(mesh, VertexWeights::Area);
    EXPECT_LT(fit.error, 1e-12 * whole_mesh_stats(graph).moments.second_moment().trace());
  }
}

TEST(TorusFitter, NoisyTorusErrorEstimatesTheExactError) {
  std::mt19937_64 rng(43);
  std::normal_distribution<double> noise(0.0, 0.003);
  for (int trial = 0; trial < 10; ++trial) {
    const Pose pose = random_pose(rng);
    const Mesh mesh = grid_mesh(30, 60, [&](double u, double v) {
      const double psi = -1 + 2.5 * u, phi = 4 * v;
      const Eigen::Vector3d normal(std::cos(psi) * std::cos(phi), std::cos(psi) * std::sin(phi),
                                   std::sin(psi));
      return pose.apply(torus_point(1, 0.3, psi, phi) + noise(rng) * normal);
    });
    Primitive torus;
    const PrimitiveFit fit = fit_whole(mesh, TorusFitter(), &torus);
    ASSERT_TRUE(fit.valid) << trial;
    EXPECT_NEAR(torus.radius, pose.scale, 0.02 * pose.scale);
    EXPECT_NEAR(torus.minor_radius, 0.3 * pose.scale, 0.02 * pose.scale);
    EXPECT_LT(angle_between_axes(torus.axis, pose.rotation.col(2)), 0.02);
    const DualGraph graph(mesh, VertexWeights::Area);
    double exact = 0;
    for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
      const Triangle corners = graph.corners(t);
      const auto w = graph.corner_weights(t);
      for (int c = 0; c < 3; ++c) {
        const Eigen::Vector3d& x = graph.position(corners[c]);
        exact += w[c] * std::pow(fit.primitive.distance({x.x(), x.y(), x.z()}), 2);
      }
    }
    // A sampled estimate (32 corners): within a factor of two of the exact Σ w d².
    EXPECT_GT(fit.error, 0.5 * exact) << trial;
    EXPECT_LT(fit.error, 2 * exact) << trial;
  }
}

// A torus fitted to a sample of 32 corners fits that sample better than the whole cluster, and the
// merge loop keeps whichever evaluation came out lowest: a noisy flat face whose torus looked
// twice as good as its plane was typed a torus (the noisy box of `primseg eval`, with tori). The
// sample's luck is measured on the principal plane, whose exact error is known, and taken out.
// A torus is valid on 18 of the 300 draws (3 of them below half the plane's error before).
TEST(TorusFitter, ANoisyFlatPatchIsNeverTwiceAsCloseToATorusAsToItsPlane) {
  std::mt19937_64 rng(2026);
  std::normal_distribution<double> noise(0.0, 0.004);
  int fitted = 0, lucky = 0;
  double smallest = 1e300;
  for (int draw = 0; draw < 300; ++draw) {
    const Pose pose = random_pose(rng);
    const Mesh mesh = grid_mesh(
        12, 12, [&](double u, double v) { return pose.apply(Eigen::Vector3d(u, v, noise(rng))); });
    Primitive torus, plane;
    const PrimitiveFit torus_fit = fit_whole(mesh, TorusFitter(), &torus);
    const PrimitiveFit plane_fit = fit_whole(mesh, PlaneFitter(), &plane);
    ASSERT_TRUE(plane_fit.valid);
    if (!torus_fit.valid) continue;
    ++fitted;
    // The torus's penalty is 2 and the plane's 1: below half, the torus would win.
    smallest = std::min(smallest, torus_fit.error / plane_fit.error);
    lucky += torus_fit.error < 0.5 * plane_fit.error;
  }
  std::printf(
      "torus error / plane error: smallest %.3f, below 0.5 in %d of %d tori fitted (300 draws)\n",
      smallest, lucky, fitted);
  EXPECT_EQ(lucky, 0);
}

TEST(TorusFitter, CylindersConesAndSpheresAreNotTori) {
  const Mesh cylinder = grid_mesh(4, 12, [](double u, double v) {
    return Vec3{std::cos(2 * v), std::sin(2 * v), 1.5 * u};
  });
  const Mesh cone = grid_mesh(4, 16, [](double u, double v) {
    const Eigen::Vector3d p = cone_point(0.7, 1 + u, 2.0 * v);
    return Vec3{p.x(), p.y(), p.z()};
  });
  const Mesh sphere = grid_mesh(6, 8, [](double u, double v) {
    const double theta = 0.4 + 0.5 * u, phi = 1.2 * v;
    return Vec3{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
  });
  for (const Mesh* mesh : {&cylinder, &cone, &sphere}) {
    Primitive p;
    const PrimitiveFit fit = fit_whole(*mesh, TorusFitter(), &p);
    EXPECT_FALSE(fit.valid) << "R " << p.radius << " r " << p.minor_radius;
  }
}

// Wedges of a CAD fillet: a quarter of the tube in 12 rows, 6 to 9 of the 48 segments round (45
// to 68 degrees), as in `primseg eval`'s filleted cylinder. Every normal line of a narrow wedge
// also nearly meets the tangent of the torus's centre circle, about which the wedge is a
// cylinder, and the best axis of the face normals' lines was that tangent: no torus was found on
// any of these, the fillet grew as spheres and cylinders at costs above zero, and the flat top
// joined a fragment of it before it was whole (seeds 1, 4, 7 and 8 with five types: mean IoU
// 0.95 to 0.97 at the true 4 regions). The axis across the tangent gives the torus exactly; with
// the normal lines through the face centroids for that axis, from 4 segments (30 degrees) on.
// Through the corners, 30-degree wedges gave no torus at any of 3 random poses. (Narrower wedges
// still converge too slowly from their rougher start: docs/method.md.)
TEST(TorusFitter, WedgesOfACadFilletAreTori) {
  std::mt19937_64 rng(59);
  const double major = 0.35, minor = 0.15, segment = 2 * M_PI / 48;
  for (int segments = 4; segments <= 9; ++segments) {
    const Pose pose = random_pose(rng);
    const Mesh wedge = grid_mesh(12, segments, [&](double u, double v) {
      return pose.apply(torus_point(major, minor, M_PI / 2 * u, segments * segment * v));
    });
    Primitive torus;
    const PrimitiveFit fit = fit_whole(wedge, TorusFitter(), &torus);
    ASSERT_TRUE(fit.valid) << segments << " segments";
    const double s = pose.scale;
    EXPECT_LT(distance(torus.point, pose.apply(Eigen::Vector3d::Zero())), 1e-6 * s) << segments;
    EXPECT_LT(angle_between_axes(torus.axis, pose.rotation.col(2)), 1e-6) << segments;
    EXPECT_NEAR(torus.radius, major * s, 1e-6 * s) << segments;
    EXPECT_NEAR(torus.minor_radius, minor * s, 1e-6 * s) << segments;
  }
}

// A CAD-style fillet (a quarter torus) and the flat top it rounds into, a fan of triangles whose
// vertices all lie on the torus's top circle, where the torus's normal is the top's: every
// vertex is on the torus, but the fan's faces leave it. The fillet is a torus, the union is not.
TEST(TorusFitter, AFlatFanOnTheTopCircleIsNotPartOfTheTorus) {
  const double major = 2, minor = 0.5, span = 1.5 * M_PI;
  const auto torus_point = [&](double tube, double around) {
    const double ring = major + minor * std::cos(tube);
    return Vec3{ring * std::cos(around), ring * std::sin(around), minor * std::sin(tube)};
  };
  const Mesh fillet =
      grid_mesh(4, 24, [&](double u, double v) { return torus_point(M_PI / 2 * u, span * v); });
  const Mesh with_top =
      with_fan_cap(fillet, [&](double t) { return torus_point(M_PI / 2, span * t); });

  Primitive p;
  const PrimitiveFit alone = fit_whole(fillet, TorusFitter(), &p);
  ASSERT_TRUE(alone.valid);
  EXPECT_NEAR(p.radius, major, 1e-6);
  EXPECT_NEAR(p.minor_radius, minor, 1e-6);
  const PrimitiveFit both = fit_whole(with_top, TorusFitter(), &p);
  EXPECT_FALSE(both.valid) << "normal agreement " << both.normal_alignment << ", R " << p.radius
                           << " r " << p.minor_radius;
}

// A CAD chamfer, one row of triangles between two circles, and the flat fan of the top it bevels,
// whose vertices all lie on the chamfer's top circle: every vertex is on two coaxial circles, and
// a one-parameter family of tori passes through both exactly. The chamfered cylinder of `primseg
// eval` (clean CAD, seeds 2 and 4, five types) merged its top and chamfer into such a torus of
// RMS 1e-16, and the automatic level took that for a true surface. The torus is not determined by
// them; with a second row of triangles (three circles) it is.
TEST(TorusFitter, CornersOnTwoCirclesDoNotDetermineATorus) {
  std::mt19937_64 rng(53);
  for (int trial = 0; trial < 8; ++trial) {
    const Pose pose = random_pose(rng);
    const double span = 1.5 * M_PI, top = 0.4, base = 0.5, height = 0.1;
    const auto ring_point = [&](double radius, double z, double around) {
      return pose.apply(Eigen::Vector3d(radius * std::cos(around), radius * std::sin(around), z));
    };
    const Mesh chamfer = grid_mesh(1, 24, [&](double u, double v) {
      return ring_point(base + (top - base) * u, height * u, span * v);
    });
    const Mesh with_top =
        with_fan_cap(chamfer, [&](double t) { return ring_point(top, height, span * t); });
    Primitive p;
    const PrimitiveFit two_circles = fit_whole(with_top, TorusFitter(), &p);
    EXPECT_FALSE(two_circles.valid) << trial << ": R " << p.radius << " r " << p.minor_radius
                                    << ", normal agreement " << two_circles.normal_alignment;

    // Three circles of a quarter torus, two rows of the same CAD tessellation: determined.
    const double major = 2, minor = 0.5;
    const Mesh fillet = grid_mesh(2, 24, [&](double u, double v) {
      const double tube = M_PI / 2 * u, ring = major + minor * std::cos(tube);
      return ring_point(ring, minor * std::sin(tube), span * v);
    });
    const PrimitiveFit three_circles = fit_whole(fillet, TorusFitter(), &p);
    ASSERT_TRUE(three_circles.valid) << trial;
    EXPECT_NEAR(p.radius, major * pose.scale, 1e-6 * pose.scale) << trial;
    EXPECT_NEAR(p.minor_radius, minor * pose.scale, 1e-6 * pose.scale) << trial;
  }
}

// A candidate that adds a few faces to a large torus patch must pay for them when they leave the
// torus. The union's own corner sample (the best 32 priorities of both parts) usually holds none
// of a small part's corners: a torus of 526 faces of rotor.off took four faces off its surface at
// a sampled RMS of 1.5e-6, against 0.0079 for a torus fitted to all 531. Each part is now sampled
// on its own.
TEST(TorusFitter, FacesAddedOffATorusPatchAreSeenByTheUnionsError) {
  std::mt19937_64 rng(47);
  for (int trial = 0; trial < 8; ++trial) {
    const Pose pose = random_pose(rng);
    // The first vertex of the grid (a corner: its one or two triangles) is lifted off the torus
    // by a tenth of the tube's radius along the torus's normal.
    bool first_vertex = true;
    const Mesh mesh = grid_mesh(30, 60, [&](double u, double v) {
      const double psi = -1 + 2.5 * u, phi = 4 * v;
      const Eigen::Vector3d normal(std::cos(psi) * std::cos(phi), std::cos(psi) * std::sin(phi),
                                   std::sin(psi));
      const double lift = first_vertex ? 0.03 : 0.0;
      first_vertex = false;
      return pose.apply(torus_point(1, 0.3, psi, phi) + lift * normal);
    });
    const DualGraph graph(mesh, VertexWeights::Area);
    std::vector<bool> in_small(mesh.face_count(), false);
    for (std::uint32_t f = 0; f < mesh.face_count(); ++f) {
      const Triangle corners = mesh.triangles[f];
      in_small[f] = corners[0] == 0 || corners[1] == 0 || corners[2] == 0;
    }
    // The two parts' statistics, accumulated as the engine does, and the edges between them.
    std::vector<bool> in_large(in_small.size());
    for (std::size_t f = 0; f < in_small.size(); ++f) in_large[f] = !in_small[f];
    const ClusterStats large = part_stats(graph, in_large), small = part_stats(graph, in_small);
    EdgeStats between;
    for (const DualEdge& e : graph.edges())
      if (in_small[e.first] != in_small[e.second]) between += e.shared;
    const PrimitiveFit fit = TorusFitter().fit(ClusterView(large, small, between));
    ASSERT_TRUE(fit.valid) << trial;
    double exact = 0;  // Σ w d² over every corner of the union, to the fitted torus
    for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
      const Triangle corners = graph.corners(t);
      const auto w = graph.corner_weights(t);
      for (int c = 0; c < 3; ++c) {
        const Eigen::Vector3d& x = graph.position(corners[c]);
        const double d = fit.primitive.distance({x.x(), x.y(), x.z()});
        exact += w[c] * (d * d);
      }
    }
    ASSERT_GT(exact, 0) << trial;
    EXPECT_GT(fit.error, 0.5 * exact) << trial;
    EXPECT_LT(fit.error, 2 * exact) << trial;
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
    EXPECT_FALSE(fit_whole(*mesh, ConeFitter(), &p).valid);
    EXPECT_FALSE(fit_whole(*mesh, TorusFitter(), &p).valid);
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

TEST(Fitters, AFitIsBeatenOnlyAtOrAboveItsErrorAndIsUnchangedOtherwise) {
  // Noisy curved patches (a sphere cap and a cylinder band) and a noisy plane, at every error to
  // beat from far below to far above each fitter's own error.
  std::mt19937_64 rng(31);
  std::normal_distribution<double> noise(0.0, 0.01);
  const Mesh cap = grid_mesh(12, 12, [&](double u, double v) {
    const double theta = 0.3 + 0.8 * u, phi = 1.5 * v;
    const double r = 1 + noise(rng);
    return Vec3{r * std::sin(theta) * std::cos(phi), r * std::sin(theta) * std::sin(phi),
                r * std::cos(theta)};
  });
  const Mesh band = grid_mesh(12, 12, [&](double u, double v) {
    const double r = 0.5 + noise(rng);
    return Vec3{r * std::cos(2 * v), r * std::sin(2 * v), 3 * u};
  });
  const Mesh plane = grid_mesh(12, 12, [&](double u, double v) { return Vec3{u, v, noise(rng)}; });
  int beaten = 0, unchanged = 0;
  for (const Mesh* mesh : {&cap, &band, &plane}) {
    const DualGraph graph(*mesh, VertexWeights::Area);
    const ClusterStats stats = whole_mesh_stats(graph);
    const ClusterView view(stats);
    for (const PrimitiveFitter* fitter :
         {static_cast<const PrimitiveFitter*>(&fitter_for(PrimitiveType::Plane)),
          &fitter_for(PrimitiveType::Cylinder), &fitter_for(PrimitiveType::Sphere)}) {
      const PrimitiveFit full = fitter->fit(view);
      if (!full.valid || !(full.error > 0)) continue;
      for (double factor : {1e-3, 0.5, 0.99, 1.01, 2.0, 1e3}) {
        const double to_beat = factor * full.error;
        const PrimitiveFit fit = fitter->fit(view, to_beat);
        if (fit.beaten) {
          ++beaten;
          EXPECT_FALSE(fit.valid);
          EXPECT_GE(full.error, to_beat * (1 - 1e-9)) << to_string(fitter->type()) << factor;
          EXPECT_LE(fit.superset_error_bound, full.error * (1 + 1e-9));
        } else {
          ++unchanged;
          EXPECT_EQ(fit.valid, full.valid);
          EXPECT_EQ(fit.error, full.error);
          EXPECT_EQ(fit.primitive.point, full.primitive.point);
          EXPECT_EQ(fit.primitive.axis, full.primitive.axis);
          EXPECT_EQ(fit.primitive.radius, full.primitive.radius);
          EXPECT_EQ(fit.normal_alignment, full.normal_alignment);
        }
      }
    }
  }
  EXPECT_GT(beaten, 0);
  EXPECT_GT(unchanged, 0);
}

}  // namespace
}  // namespace primseg
