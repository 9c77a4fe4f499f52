#include "primseg/primitive.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "eigen_conversions.hpp"

namespace primseg {
namespace {

constexpr std::string_view kNames[kPrimitiveTypeCount] = {"plane", "cylinder", "sphere", "cone",
                                                          "torus"};

using detail::to_eigen;
using detail::to_vec3;

// Any unit vector orthogonal to the unit vector a.
Eigen::Vector3d orthogonal_to(const Eigen::Vector3d& a) {
  Eigen::Index least;
  a.cwiseAbs().minCoeff(&least);
  return a.cross(Eigen::Vector3d::Unit(least)).normalized();
}

// The unit direction of d's part orthogonal to the unit vector a; any such direction when d is
// on the line of a. The axial part is subtracted twice: near the line, one subtraction leaves
// round-off of d's size in every direction, along a too, and the direction of what is left would
// not be orthogonal to a (a point 1e-17 from a cylinder's axis went to a point 0.6 radii along it,
// off the surface).
Eigen::Vector3d radial_direction(const Eigen::Vector3d& d, const Eigen::Vector3d& a) {
  Eigen::Vector3d radial = d - a * a.dot(d);
  radial -= a * a.dot(radial);
  return radial.squaredNorm() > 0 ? Eigen::Vector3d(radial.normalized()) : orthogonal_to(a);
}

}  // namespace

std::string_view to_string(PrimitiveType type) {
  const auto index = static_cast<std::size_t>(type);
  return index < kPrimitiveTypeCount ? kNames[index] : std::string_view("unknown");
}

std::vector<NamedParameter> named_parameters(const Primitive& p) {
  const auto vector = [](std::string_view name, const Vec3& v) {
    return NamedParameter{name, true, v};
  };
  const auto scalar = [](std::string_view name, double v) {
    return NamedParameter{name, false, {v, 0, 0}};
  };
  switch (p.type) {
    case PrimitiveType::Plane:
      return {vector("normal", p.axis), vector("point", p.point)};
    case PrimitiveType::Sphere:
      return {vector("center", p.point), scalar("radius", p.radius)};
    case PrimitiveType::Cylinder:
      return {vector("axis", p.axis), vector("point", p.point), scalar("radius", p.radius)};
    case PrimitiveType::Cone:
      return {vector("apex", p.point), vector("axis", p.axis), scalar("half_angle", p.half_angle)};
    case PrimitiveType::Torus:
      return {vector("center", p.point), vector("axis", p.axis), scalar("major_radius", p.radius),
              scalar("minor_radius", p.minor_radius)};
  }
  return {};
}

std::optional<PrimitiveType> primitive_type_from_string(std::string_view name) {
  for (int t = 0; t < kPrimitiveTypeCount; ++t)
    if (kNames[t] == name) return static_cast<PrimitiveType>(t);
  return std::nullopt;
}

double Primitive::distance(const Vec3& x) const {
  const Eigen::Vector3d p = to_eigen(x);
  return (p - to_eigen(closest_point(x))).norm();
}

Vec3 Primitive::closest_point(const Vec3& x) const {
  const Eigen::Vector3d p = to_eigen(x);
  const Eigen::Vector3d origin = to_eigen(point);
  const Eigen::Vector3d a = to_eigen(axis);
  switch (type) {
    case PrimitiveType::Plane:
      return to_vec3(p - a * a.dot(p - origin));
    case PrimitiveType::Sphere: {
      Eigen::Vector3d d = p - origin;
      if (d.squaredNorm() == 0) d = Eigen::Vector3d::UnitX();
      return to_vec3(origin + d.normalized() * radius);
    }
    case PrimitiveType::Cylinder: {
      const Eigen::Vector3d d = p - origin;
      return to_vec3(origin + a * a.dot(d) + radial_direction(d, a) * radius);
    }
    case PrimitiveType::Cone: {
      // In the half-plane through the axis and p: the generator leaves the apex at half_angle.
      const Eigen::Vector3d d = p - origin;
      const Eigen::Vector3d generator =
          a * std::cos(half_angle) + radial_direction(d, a) * std::sin(half_angle);
      const double t = std::max(0.0, d.dot(generator));
      return to_vec3(origin + generator * t);
    }
    case PrimitiveType::Torus: {
      const Eigen::Vector3d ring = origin + radial_direction(p - origin, a) * radius;
      Eigen::Vector3d to_p = p - ring;
      if (to_p.squaredNorm() == 0) to_p = a;
      return to_vec3(ring + to_p.normalized() * minor_radius);
    }
  }
  return x;
}

Vec3 Primitive::normal(const Vec3& x) const {
  const Eigen::Vector3d p = to_eigen(x);
  const Eigen::Vector3d origin = to_eigen(point);
  const Eigen::Vector3d a = to_eigen(axis);
  switch (type) {
    case PrimitiveType::Plane:
      return axis;
    case PrimitiveType::Sphere: {
      const Eigen::Vector3d d = p - origin;
      return d.squaredNorm() > 0 ? to_vec3(d.normalized()) : Vec3{1, 0, 0};
    }
    case PrimitiveType::Cylinder:
      return to_vec3(radial_direction(p - origin, a));
    case PrimitiveType::Cone:
      // Orthogonal to the generator a cos + u sin in the half-plane of p, away from the axis.
      return to_vec3(radial_direction(p - origin, a) * std::cos(half_angle) -
                     a * std::sin(half_angle));
    case PrimitiveType::Torus: {
      const Eigen::Vector3d ring = origin + radial_direction(p - origin, a) * radius;
      const Eigen::Vector3d to_p = p - ring;
      return to_p.squaredNorm() > 0 ? to_vec3(to_p.normalized()) : axis;
    }
  }
  return axis;
}

}  // namespace primseg
