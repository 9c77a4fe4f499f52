#pragma once
/// @file cone.hpp
/// The cone fitter (see cone.cpp for the method).

#include "primseg/primitives/primitive_fitter.hpp"

namespace primseg {

/// Half-angles a cone may have, radians: below kMinConeHalfAngle a cone is reported as the
/// cylinder it nearly is, above π/2 − kMinConeHalfAngle as the plane it nearly is.
inline constexpr double kMinConeHalfAngle = 2 * 3.14159265358979323846 / 180;

class ConeFitter final : public PrimitiveFitter {
 public:
  PrimitiveType type() const override { return PrimitiveType::Cone; }
  std::uint32_t min_triangles() const override;
  using PrimitiveFitter::fit;
  PrimitiveFit fit(const ClusterView& cluster, double error_to_beat) const override;
  bool closed_form() const override { return false; }
};

}  // namespace primseg
