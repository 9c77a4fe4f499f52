#pragma once
/// @file cylinder.hpp
/// The cylinder fitter (see cylinder.cpp for the method).

#include "primseg/primitives/primitive_fitter.hpp"

namespace primseg {

class CylinderFitter final : public PrimitiveFitter {
 public:
  PrimitiveType type() const override { return PrimitiveType::Cylinder; }
  std::uint32_t min_triangles() const override;
  using PrimitiveFitter::fit;
  PrimitiveFit fit(const ClusterView& cluster, double error_to_beat) const override;
};

}  // namespace primseg
