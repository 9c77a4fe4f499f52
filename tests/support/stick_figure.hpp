#pragma once
// A generated stick figure with ground truth, for the skeleton and skinning tests: a cylinder
// torso (axis z, open at the bottom), a sphere head closing its top, two arms (upper arm
// straight out along ±x, forearm mitred at the elbow and bent down) and two legs (down and out),
// every limb an exact cylinder open at its far end. Limbs meet the torso along their exact
// intersection curves, so every vertex lies on its region's surface and the mesh is conforming.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "primseg/mesh.hpp"

namespace primseg::testing {

struct StickFigure {
  Mesh mesh;
  /// Ground-truth part of each face, shape (F), indexing `parts`.
  std::vector<std::uint32_t> part_of_face;
  /// Names: torso, head, upper_arm_left, upper_arm_right, forearm_left, forearm_right,
  /// leg_left, leg_right (left is -x).
  std::vector<std::string> parts;
  /// Where each limb's axis crosses the torso's surface (shoulders, hips), by part index (zero for
  /// torso and head).
  std::vector<Vec3> attachment;
  /// Elbow centres: where the upper arm and forearm axes meet, [left, right].
  std::array<Vec3, 2> elbow{};
  /// Unit directions of the parts' axes (torso: z).
  std::vector<Vec3> axis;
  double torso_radius = 1.0;
  double arm_radius = 0.35;
  double leg_radius = 0.4;

  std::uint32_t part(const std::string& name) const;
};

/// The figure with triangles of about `edge` (in units of the torso radius, 1).
StickFigure make_stick_figure(double edge = 0.12);

}  // namespace primseg::testing
