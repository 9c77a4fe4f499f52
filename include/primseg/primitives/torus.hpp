#pragma once
/// @file torus.hpp
/// The torus fitter (see torus.cpp for the method).

#include "primseg/primitives/primitive_fitter.hpp"

namespace primseg {

/// A torus whose major radius is below this fraction of its minor radius is the sphere it nearly
/// is (a sphere is a torus of major radius 0 about any axis through its centre): the fitter
/// rejects it, and a cluster report whose geometric fit ends there reports the sphere instead.
inline constexpr double kMinRelativeTorusMajorRadius = 0.05;

/// Whether a torus's ring is below kMinRelativeTorusMajorRadius of its tube (or not a number).
inline bool torus_ring_vanishes(const Primitive& torus) {
  return !(torus.radius >= kMinRelativeTorusMajorRadius * torus.minor_radius);
}

class TorusFitter final : public PrimitiveFitter {
 public:
  PrimitiveType type() const override { return PrimitiveType::Torus; }
  std::uint32_t min_triangles() const override;
  using PrimitiveFitter::fit;
  PrimitiveFit fit(const ClusterView& cluster, double error_to_beat) const override;
  bool closed_form() const override { return false; }
  bool needs_samples() const override { return true; }
};

}  // namespace primseg
