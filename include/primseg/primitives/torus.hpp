#pragma once
/// @file torus.hpp
/// The torus fitter (see torus.cpp for the method).

#include "primseg/primitives/primitive_fitter.hpp"

namespace primseg {

class TorusFitter final : public PrimitiveFitter {
 public:
  PrimitiveType type() const override { return PrimitiveType::Torus; }
  std::uint32_t min_triangles() const override;
  using PrimitiveFitter::fit;
  PrimitiveFit fit(const ClusterView& cluster, double error_to_beat) const override;
  bool needs_samples() const override { return true; }
};

}  // namespace primseg
