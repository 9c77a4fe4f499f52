#include "primseg/primitives/primitive_fitter.hpp"

#include <algorithm>
#include <optional>
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

PrimitiveType fittable_type_from_string(std::string_view name) {
  const std::optional<PrimitiveType> type = primitive_type_from_string(name);
  if (type && has_fitter(*type)) return *type;
  std::string available;
  for (int t = 0; t < kPrimitiveTypeCount; ++t)
    if (has_fitter(static_cast<PrimitiveType>(t)))
      available += (available.empty() ? "'" : ", '") +
                   std::string(to_string(static_cast<PrimitiveType>(t))) + "'";
  throw InvalidInputError("unknown primitive '" + std::string(name) + "' (available: " + available +
                          ")");
}

std::vector<PrimitiveType> fittable_types_from_list(std::string_view list) {
  std::vector<PrimitiveType> types;
  for (std::size_t begin = 0;;) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    types.push_back(fittable_type_from_string(list.substr(begin, end - begin)));
    if (end == list.size()) return types;
    begin = end + 1;
  }
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
