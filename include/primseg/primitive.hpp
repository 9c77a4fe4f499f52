#pragma once
/// @file primitive.hpp
/// Primitive types and their parameters, as reported to users (in input units).

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "primseg/mesh.hpp"

namespace primseg {

/// The kinds of primitive a cluster can be fitted with. The numeric values are stored in tree
/// files: never renumber them. Their order is also the tie order of model selection: on equal
/// penalised error the lower value wins.
enum class PrimitiveType : std::uint8_t {
  Plane = 0,
  Cylinder = 1,
  Sphere = 2,
  Cone = 3,
  Torus = 4
};

inline constexpr int kPrimitiveTypeCount = 5;

/// Lower-case name ("plane", "cylinder", "sphere", "cone", "torus").
std::string_view to_string(PrimitiveType type);
/// Inverse of to_string; std::nullopt for an unknown name.
std::optional<PrimitiveType> primitive_type_from_string(std::string_view name);

/// A fitted primitive. Which fields are meaningful depends on `type`; the others are zero.
/// - Plane: `point` = weighted centroid of the cluster, `axis` = unit normal, oriented along the
///   cluster's summed area-weighted face normals.
/// - Sphere: `point` = centre, `radius`.
/// - Cylinder: `point` = the cluster's centroid projected on the axis, `axis` = unit direction
///   with its largest-magnitude component positive, `radius`.
/// - Cone: `point` = apex, `axis` = unit direction from the apex into the cone, `half_angle`
///   in radians.
/// - Torus: `point` = centre, `axis` = unit normal of the equatorial plane (largest-magnitude
///   component positive), `radius` = major radius, `minor_radius`.
struct Primitive {
  PrimitiveType type = PrimitiveType::Plane;
  Vec3 point{0, 0, 0};
  Vec3 axis{0, 0, 0};
  double radius = 0;
  double minor_radius = 0;
  double half_angle = 0;

  /// Unsigned Euclidean distance from x to the primitive's surface (input units).
  double distance(const Vec3& x) const;
  /// The point of the primitive's surface closest to x. Where several are (x at a sphere's
  /// centre, on the axis of a cylinder, cone or torus, on a torus's core circle), one of them.
  Vec3 closest_point(const Vec3& x) const;
  /// Unit normal of the surface at closest_point(x): a plane's `axis`; for the other types the
  /// direction away from the centre, axis or core circle (outward on a sphere, a cylinder, a cone
  /// and a torus seen from outside). Where the closest point is one of several, the normal at
  /// the one closest_point() picks; at a cone's apex, that of the generator through it.
  Vec3 normal(const Vec3& x) const;
};

/// One parameter of a primitive as users see it: a named 3-vector or scalar, input units.
struct NamedParameter {
  std::string_view name;   ///< e.g. "normal", "radius"
  bool is_vector = false;  ///< true: all of `value`; false: a scalar in value[0]
  Vec3 value{0, 0, 0};
};

/// The parameters that describe a primitive to users, in input units (what the CLI's JSON
/// "params" and the Python bindings' cluster dictionaries hold): plane {normal, point}, sphere
/// {center, radius}, cylinder {axis, point, radius}, cone {apex, axis, half_angle (radians)},
/// torus {center, axis, major_radius, minor_radius}.
std::vector<NamedParameter> named_parameters(const Primitive& primitive);

}  // namespace primseg
