#pragma once
// A primitive's parameters from input units to a dual graph's working frame (the inverse of
// WorkingFrame::to_input).

#include <cmath>

#include "primseg/dual_graph.hpp"

namespace primseg::detail {

inline Primitive to_working(const WorkingFrame& frame, const Primitive& input) {
  Primitive working = input;
  const Eigen::Vector3d p = frame.to_working(input.point);
  working.point = {p.x(), p.y(), p.z()};
  working.radius = std::ldexp(input.radius, -frame.exponent);
  working.minor_radius = std::ldexp(input.minor_radius, -frame.exponent);
  return working;
}

}  // namespace primseg::detail
