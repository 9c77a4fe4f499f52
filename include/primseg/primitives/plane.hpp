#pragma once
/// @file plane.hpp
/// The plane fitter (see plane.cpp for the method).

#include "primseg/primitives/primitive_fitter.hpp"

namespace primseg {

class PlaneFitter final : public PrimitiveFitter {
 public:
  PrimitiveType type() const override { return PrimitiveType::Plane; }
  std::uint32_t min_triangles() const override;
  using PrimitiveFitter::fit;
  PrimitiveFit fit(const ClusterView& cluster, double error_to_beat) const override;
};

}  // namespace primseg
