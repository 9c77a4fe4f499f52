#pragma once
/// @file sphere.hpp
/// The sphere fitter (see sphere.cpp for the method).

#include "primseg/primitives/primitive_fitter.hpp"

namespace primseg {

class SphereFitter final : public PrimitiveFitter {
 public:
  PrimitiveType type() const override { return PrimitiveType::Sphere; }
  std::uint32_t min_triangles() const override;
  using PrimitiveFitter::fit;
  PrimitiveFit fit(const ClusterView& cluster, double error_to_beat) const override;
};

}  // namespace primseg
