#include "primseg/primitives/primitive_fitter.hpp"

#include <string>

#include "primseg/error.hpp"
#include "primseg/primitives/cone.hpp"
#include "primseg/primitives/cylinder.hpp"
#include "primseg/primitives/plane.hpp"
#include "primseg/primitives/sphere.hpp"
#include "primseg/primitives/torus.hpp"

namespace primseg {
namespace {

const PrimitiveFitter* find_fitter(PrimitiveType type) {
  static const PlaneFitter plane;
  static const CylinderFitter cylinder;
  static const SphereFitter sphere;
  static const ConeFitter cone;
  static const TorusFitter torus;
  switch (type) {
    case PrimitiveType::Plane:
      return &plane;
    case PrimitiveType::Cylinder:
      return &cylinder;
    case PrimitiveType::Sphere:
      return &sphere;
    case PrimitiveType::Cone:
      return &cone;
    case PrimitiveType::Torus:
      return &torus;
    default:
      return nullptr;
  }
}

}  // namespace

bool has_fitter(PrimitiveType type) {
  return find_fitter(type) != nullptr;
}

const PrimitiveFitter& fitter_for(PrimitiveType type) {
  const PrimitiveFitter* fitter = find_fitter(type);
  if (!fitter)
    throw InvalidInputError("primitive type '" + std::string(to_string(type)) +
                            "' is not available in this version");
  return *fitter;
}

Eigen::Vector3d canonical_axis(const Eigen::Vector3d& axis) {
  Eigen::Index largest;
  axis.cwiseAbs().maxCoeff(&largest);
  return axis(largest) < 0 ? Eigen::Vector3d(-axis) : axis;
}

}  // namespace primseg
