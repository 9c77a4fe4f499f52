// Primitive::closest_point, distance and normal against a dense sampling of each surface at random
// poses, the query points where the nearest point is not unique (a centre, an axis, a tube's core,
// behind an apex), and the names users see for types and parameters.

#include "primseg/primitive.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "support/test_support.hpp"

namespace primseg {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRadius = 0.7, kMinorRadius = 0.3, kHalfAngle = 0.5;
// Half the side of the sampled square of unbounded surfaces (plane, cylinder, cone).
constexpr double kExtent = 4.0;

// A primitive given in a local frame (axis z, apex or centre at the origin) and placed by a
// rotation and a translation; `on_surface` is the distance of a local point to the surface,
// written independently of the library.
struct PlacedPrimitive {
  Primitive primitive;
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  std::function<double(const Eigen::Vector3d&)> local_distance;
  std::function<Eigen::Vector3d(double, double)> local_sample;  // (u, v) in [0, 1]²

  Vec3 to_world(const Eigen::Vector3d& local) const {
    const Eigen::Vector3d x = rotation * local + translation;
    return {x.x(), x.y(), x.z()};
  }
  Eigen::Vector3d to_local(const Vec3& world) const {
    return rotation.transpose() * (Eigen::Vector3d(world[0], world[1], world[2]) - translation);
  }
};

double planar_radius(const Eigen::Vector3d& x) {
  return std::hypot(x.x(), x.y());
}

// The unit vector at these angles (radians) from the z axis and, around it, from the x axis.
Eigen::Vector3d direction(double polar, double azimuth) {
  return {std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth),
          std::cos(polar)};
}

// Every type at a random pose. The sampled part of each unbounded surface contains the nearest
// points of queries in the cube [-1, 1]³ of the local frame.
std::vector<PlacedPrimitive> placed_primitives(std::mt19937_64& rng) {
  std::vector<PlacedPrimitive> placed(kPrimitiveTypeCount);
  for (int t = 0; t < kPrimitiveTypeCount; ++t) {
    PlacedPrimitive& p = placed[t];
    const auto r = testing::random_rotation(rng);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) p.rotation(i, j) = r[i][j];
    std::uniform_real_distribution<double> offset(-2, 2);
    p.translation = {offset(rng), offset(rng), offset(rng)};
    p.primitive.type = static_cast<PrimitiveType>(t);
    p.primitive.point = p.to_world(Eigen::Vector3d::Zero());
    const Eigen::Vector3d axis = p.rotation.col(2);
    p.primitive.axis = {axis.x(), axis.y(), axis.z()};
    switch (p.primitive.type) {
      case PrimitiveType::Plane:
        p.local_distance = [](const Eigen::Vector3d& x) { return std::abs(x.z()); };
        p.local_sample = [](double u, double v) -> Eigen::Vector3d {
          return Eigen::Vector3d(kExtent * (2 * u - 1), kExtent * (2 * v - 1), 0);
        };
        break;
      case PrimitiveType::Sphere:
        p.primitive.radius = kRadius;
        p.local_distance = [](const Eigen::Vector3d& x) { return std::abs(x.norm() - kRadius); };
        p.local_sample = [](double u, double v) -> Eigen::Vector3d {
          return kRadius * direction(kPi * u, 2 * kPi * v);
        };
        break;
      case PrimitiveType::Cylinder:
        p.primitive.radius = kRadius;
        p.local_distance = [](const Eigen::Vector3d& x) {
          return std::abs(planar_radius(x) - kRadius);
        };
        p.local_sample = [](double u, double v) -> Eigen::Vector3d {
          return Eigen::Vector3d(kRadius * std::cos(2 * kPi * u), kRadius * std::sin(2 * kPi * u),
                                 kExtent * (2 * v - 1));
        };
        break;
      case PrimitiveType::Cone:
        p.primitive.half_angle = kHalfAngle;
        // In the half-plane through the axis: the distance to the generator ray from the apex.
        p.local_distance = [](const Eigen::Vector3d& x) {
          const Eigen::Vector2d point(planar_radius(x), x.z());
          const Eigen::Vector2d generator(std::sin(kHalfAngle), std::cos(kHalfAngle));
          return (point - std::max(0.0, point.dot(generator)) * generator).norm();
        };
        p.local_sample = [](double u, double v) -> Eigen::Vector3d {
          return kExtent * u * direction(kHalfAngle, 2 * kPi * v);
        };
        break;
      case PrimitiveType::Torus:
        p.primitive.radius = kRadius;
        p.primitive.minor_radius = kMinorRadius;
        p.local_distance = [](const Eigen::Vector3d& x) {
          return std::abs(std::hypot(planar_radius(x) - kRadius, x.z()) - kMinorRadius);
        };
        p.local_sample = [](double u, double v) -> Eigen::Vector3d {
          const double around = 2 * kPi * u, tube = 2 * kPi * v;
          const double ring = kRadius + kMinorRadius * std::cos(tube);
          return Eigen::Vector3d(ring * std::cos(around), ring * std::sin(around),
                                 kMinorRadius * std::sin(tube));
        };
        break;
    }
  }
  return placed;
}

TEST(Primitive, ClosestPointIsOnTheSurfaceAndNoSampleOfItIsNearer) {
  std::mt19937_64 rng(20261126);
  std::uniform_real_distribution<double> coordinate(-1, 1);
  constexpr int kSamplesPerSide = 500;
  for (int pose = 0; pose < 3; ++pose)
    for (const PlacedPrimitive& placed : placed_primitives(rng)) {
      SCOPED_TRACE(std::string(to_string(placed.primitive.type)) + ", pose " +
                   std::to_string(pose));
      std::vector<Vec3> samples;
      for (int i = 0; i <= kSamplesPerSide; ++i)
        for (int j = 0; j <= kSamplesPerSide; ++j)
          samples.push_back(placed.to_world(
              placed.local_sample(double(i) / kSamplesPerSide, double(j) / kSamplesPerSide)));
      for (int query = 0; query < 40; ++query) {
        const Vec3 x = placed.to_world({coordinate(rng), coordinate(rng), coordinate(rng)});
        const Vec3 nearest = placed.primitive.closest_point(x);
        const double distance = placed.primitive.distance(x);
        EXPECT_LE(placed.local_distance(placed.to_local(nearest)), 1e-12);
        EXPECT_NEAR(distance, std::hypot(x[0] - nearest[0], x[1] - nearest[1], x[2] - nearest[2]),
                    1e-15);
        EXPECT_NEAR(distance, placed.local_distance(placed.to_local(x)), 1e-12);
        double nearest_sample = std::numeric_limits<double>::infinity();
        for (const Vec3& s : samples)
          nearest_sample =
              std::min(nearest_sample, std::hypot(x[0] - s[0], x[1] - s[1], x[2] - s[2]));
        EXPECT_LE(distance, nearest_sample + 1e-12);
        // The sampling is fine enough that it finds the same point within its spacing.
        EXPECT_LE(nearest_sample, distance + 0.03);
      }
    }
}

// Where every direction is as near (the surface all around the query), closest_point still
// returns a point of the surface at the right distance.
TEST(Primitive, QueriesWithoutAUniqueNearestPoint) {
  std::mt19937_64 rng(7);
  const std::vector<PlacedPrimitive> placed = placed_primitives(rng);
  auto expect_nearest = [&](PrimitiveType type, const Eigen::Vector3d& local_query,
                            double expected_distance) {
    SCOPED_TRACE(std::string(to_string(type)));
    const PlacedPrimitive& p = placed[static_cast<std::size_t>(type)];
    const Vec3 x = p.to_world(local_query);
    const Vec3 nearest = p.primitive.closest_point(x);
    EXPECT_LE(p.local_distance(p.to_local(nearest)), 1e-12);
    EXPECT_NEAR(p.primitive.distance(x), expected_distance, 1e-12);
  };
  expect_nearest(PrimitiveType::Sphere, {0, 0, 0}, kRadius);
  expect_nearest(PrimitiveType::Cylinder, {0, 0, 0.4}, kRadius);
  // On the cone's axis inside it, and behind its apex (the apex is nearest).
  expect_nearest(PrimitiveType::Cone, {0, 0, 0.8}, 0.8 * std::sin(kHalfAngle));
  expect_nearest(PrimitiveType::Cone, {0, 0, -0.6}, 0.6);
  // On the torus's axis, and on the circle at the core of its tube.
  expect_nearest(PrimitiveType::Torus, {0, 0, 0.25}, std::hypot(kRadius, 0.25) - kMinorRadius);
  expect_nearest(PrimitiveType::Torus, {0, kRadius, 0}, kMinorRadius);
}

// The normal is the gradient of the distance (central differences of the independent local
// distance) wherever the query is off the surface and has one nearest point, and points away
// from the centre, axis or core circle.
TEST(Primitive, NormalIsTheDistanceGradientAndPointsAway) {
  std::mt19937_64 rng(20261127);
  std::uniform_real_distribution<double> coordinate(-1, 1);
  constexpr double kStep = 1e-6;
  for (int pose = 0; pose < 3; ++pose)
    for (const PlacedPrimitive& placed : placed_primitives(rng)) {
      const PrimitiveType type = placed.primitive.type;
      SCOPED_TRACE(std::string(to_string(type)) + ", pose " + std::to_string(pose));
      for (int query = 0; query < 200; ++query) {
        const Eigen::Vector3d local(coordinate(rng), coordinate(rng), coordinate(rng));
        const Eigen::Vector2d radial_plane(planar_radius(local), local.z());
        // Behind a cone's apex the apex is nearest and the distance's gradient is not a normal.
        if (type == PrimitiveType::Cone &&
            radial_plane.dot(Eigen::Vector2d(std::sin(kHalfAngle), std::cos(kHalfAngle))) <= 0)
          continue;
        const Vec3 x = placed.to_world(local);
        const Vec3 n = placed.primitive.normal(x);
        const Eigen::Vector3d world_normal(n[0], n[1], n[2]);
        EXPECT_NEAR(world_normal.norm(), 1, 1e-15);
        Eigen::Vector3d gradient;
        for (int i = 0; i < 3; ++i) {
          Eigen::Vector3d step = Eigen::Vector3d::Zero();
          step[i] = kStep;
          gradient[i] =
              (placed.local_distance(local + step) - placed.local_distance(local - step)) /
              (2 * kStep);
        }
        const Eigen::Vector3d local_normal = placed.rotation.transpose() * world_normal;
        EXPECT_NEAR(std::abs(gradient.dot(local_normal)), 1, 1e-6);
        const Eigen::Vector3d radial(local.x(), local.y(), 0);
        switch (type) {
          case PrimitiveType::Plane:
            EXPECT_EQ(n, placed.primitive.axis);
            break;
          case PrimitiveType::Sphere:
            EXPECT_GT(local_normal.dot(local), 0);
            break;
          case PrimitiveType::Cylinder:
            EXPECT_GT(local_normal.dot(radial), 0);
            break;
          case PrimitiveType::Cone:
            EXPECT_GT(local_normal.dot(radial), 0);
            EXPECT_LT(local_normal.z(), 0);  // the cone opens along +z
            break;
          case PrimitiveType::Torus:
            EXPECT_GT(local_normal.dot(local - kRadius * radial.normalized()), 0);
            break;
        }
      }
    }
}

TEST(Primitive, ParametersAndTypesByName) {
  Primitive p;
  p.point = {1, 2, 3};
  p.axis = {0, 0, 1};
  p.radius = 4;
  p.minor_radius = 0.5;
  p.half_angle = 0.25;
  auto described = [&](PrimitiveType type) {
    p.type = type;
    std::vector<std::string> names;
    std::vector<Vec3> values;
    for (const NamedParameter& parameter : named_parameters(p)) {
      names.emplace_back(std::string(parameter.name) + (parameter.is_vector ? "[3]" : ""));
      values.push_back(parameter.value);
    }
    return std::make_pair(names, values);
  };
  const Vec3 point = p.point, axis = p.axis;
  using Names = std::vector<std::string>;
  using Values = std::vector<Vec3>;
  EXPECT_EQ(described(PrimitiveType::Plane),
            std::make_pair(Names{"normal[3]", "point[3]"}, Values{axis, point}));
  EXPECT_EQ(described(PrimitiveType::Sphere),
            std::make_pair(Names{"center[3]", "radius"}, Values{point, {4, 0, 0}}));
  EXPECT_EQ(described(PrimitiveType::Cylinder),
            std::make_pair(Names{"axis[3]", "point[3]", "radius"}, Values{axis, point, {4, 0, 0}}));
  EXPECT_EQ(
      described(PrimitiveType::Cone),
      std::make_pair(Names{"apex[3]", "axis[3]", "half_angle"}, Values{point, axis, {0.25, 0, 0}}));
  EXPECT_EQ(described(PrimitiveType::Torus),
            std::make_pair(Names{"center[3]", "axis[3]", "major_radius", "minor_radius"},
                           Values{point, axis, {4, 0, 0}, {0.5, 0, 0}}));

  for (int t = 0; t < kPrimitiveTypeCount; ++t) {
    const auto type = static_cast<PrimitiveType>(t);
    EXPECT_EQ(primitive_type_from_string(to_string(type)), type);
  }
  EXPECT_EQ(to_string(PrimitiveType::Cylinder), "cylinder");
  EXPECT_EQ(to_string(static_cast<PrimitiveType>(kPrimitiveTypeCount)), "unknown");
  EXPECT_EQ(primitive_type_from_string("Plane"), std::nullopt);
  EXPECT_EQ(primitive_type_from_string(""), std::nullopt);
  EXPECT_EQ(primitive_type_from_string("unknown"), std::nullopt);
}

}  // namespace
}  // namespace primseg
