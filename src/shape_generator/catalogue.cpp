#include "catalogue.hpp"

#include <array>
#include <cmath>
#include <numbers>

#include "vector_math.hpp"

namespace primseg::shape_detail {
namespace {

constexpr double kPi = std::numbers::pi;
const Vec3 kUp{0, 0, 1};

double diagonal(const Vec3& size) {
  return norm(size);
}

/// One planar face through `corners` (joined by straight edges), with optional hole loops.
std::uint32_t plane_face(PatchBuilder& builder, const std::vector<std::uint32_t>& corners,
                         const Vec3& outward, std::vector<std::vector<std::uint32_t>> holes = {}) {
  const std::uint32_t region = builder.add_plane(builder.positions()[corners[0]], outward);
  std::vector<std::vector<std::uint32_t>> loops{builder.polygon_loop(corners)};
  for (auto& hole : holes) loops.push_back(std::move(hole));
  builder.planar_patch(region, loops);
  return region;
}

/// A planar disc bounded by a ring.
std::uint32_t disc_face(PatchBuilder& builder, const Ring& rim, const Vec3& outward) {
  const std::uint32_t region = builder.add_plane(builder.positions()[rim.vertices[0]], outward);
  builder.planar_patch(region, {rim.vertices});
  return region;
}

/// Corners of the box [lo, hi]; corner index bit 0 selects x = hi, bit 1 y = hi, bit 2 z = hi.
std::array<std::uint32_t, 8> box_corners(PatchBuilder& builder, const Vec3& lo, const Vec3& hi) {
  std::array<std::uint32_t, 8> corners{};
  for (int c = 0; c < 8; ++c) {
    corners[c] = builder.add_vertex(
        {(c & 1) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1], (c & 4) ? hi[2] : lo[2]});
  }
  return corners;
}

/// The six faces of a box in the order -x, +x, -y, +y, -z, +z, with holes in the bottom and top.
void box_faces(PatchBuilder& builder, const std::array<std::uint32_t, 8>& c,
               std::vector<std::vector<std::uint32_t>> bottom_holes = {},
               std::vector<std::vector<std::uint32_t>> top_holes = {}) {
  plane_face(builder, {c[0], c[2], c[6], c[4]}, {-1, 0, 0});
  plane_face(builder, {c[1], c[3], c[7], c[5]}, {1, 0, 0});
  plane_face(builder, {c[0], c[1], c[5], c[4]}, {0, -1, 0});
  plane_face(builder, {c[2], c[3], c[7], c[6]}, {0, 1, 0});
  plane_face(builder, {c[0], c[1], c[3], c[2]}, {0, 0, -1}, std::move(bottom_holes));
  plane_face(builder, {c[4], c[5], c[7], c[6]}, {0, 0, 1}, std::move(top_holes));
}

// The box shared by most shapes: 1.6 x 1.2 x 0.8, centred on the origin. Unequal sides keep
// the faces distinguishable.
const Vec3 kBoxLo{-0.8, -0.6, -0.4}, kBoxHi{0.8, 0.6, 0.4};

PatchBuilder box(const ShapeOptions& options) {
  PatchBuilder builder(options, diagonal(kBoxHi - kBoxLo));
  box_faces(builder, box_corners(builder, kBoxLo, kBoxHi));
  return builder;
}

PatchBuilder slanted_box(const ShapeOptions& options) {
  PatchBuilder builder(options, diagonal(kBoxHi - kBoxLo));
  std::array<std::uint32_t, 7> c{};  // box corners but the cut one, numbered as in box_corners
  for (int k = 0; k < 7; ++k) {
    c[k] = builder.add_vertex({(k & 1) ? kBoxHi[0] : kBoxLo[0], (k & 2) ? kBoxHi[1] : kBoxLo[1],
                               (k & 4) ? kBoxHi[2] : kBoxLo[2]});
  }
  // The cut plane meets the three edges out of corner 7 at these distances from it.
  const double cut_x = 0.6, cut_y = 0.45, cut_z = 0.35;
  const std::uint32_t px = builder.add_vertex({kBoxHi[0] - cut_x, kBoxHi[1], kBoxHi[2]});
  const std::uint32_t py = builder.add_vertex({kBoxHi[0], kBoxHi[1] - cut_y, kBoxHi[2]});
  const std::uint32_t pz = builder.add_vertex({kBoxHi[0], kBoxHi[1], kBoxHi[2] - cut_z});
  plane_face(builder, {c[0], c[2], c[6], c[4]}, {-1, 0, 0});
  plane_face(builder, {c[1], c[3], pz, py, c[5]}, {1, 0, 0});
  plane_face(builder, {c[0], c[1], c[5], c[4]}, {0, -1, 0});
  plane_face(builder, {c[2], c[3], pz, px, c[6]}, {0, 1, 0});
  plane_face(builder, {c[0], c[1], c[3], c[2]}, {0, 0, -1});
  plane_face(builder, {c[4], c[5], py, px, c[6]}, {0, 0, 1});
  plane_face(builder, {px, py, pz}, {1 / cut_x, 1 / cut_y, 1 / cut_z});
  return builder;
}

PatchBuilder capped_cylinder(const ShapeOptions& options) {
  const double radius = 0.5, height = 1.2;
  PatchBuilder builder(options, diagonal({2 * radius, 2 * radius, height}));
  const CircleFrame frame = CircleFrame::around({0, 0, -height / 2}, kUp);
  const int count = builder.arc_segments(radius, 2 * kPi);
  const Ring bottom = builder.circle(frame, radius, 0, count);
  const Ring top = builder.circle(frame, radius, height, count);
  builder.cylinder_patch(builder.add_cylinder(frame, radius, false), frame, radius, 0, height,
                         bottom, top);
  disc_face(builder, bottom, {0, 0, -1});
  disc_face(builder, top, kUp);
  return builder;
}

PatchBuilder sphere(const ShapeOptions& options) {
  const double radius = 0.8;
  PatchBuilder builder(options, diagonal({2 * radius, 2 * radius, 2 * radius}));
  const std::uint32_t region = builder.add_sphere({0, 0, 0}, radius, false);
  if (builder.cad()) {
    const CircleFrame frame = CircleFrame::around({0, 0, 0}, kUp);
    builder.sphere_patch(region, frame, radius, 0, kPi, builder.pole({0, 0, radius}),
                         builder.pole({0, 0, -radius}));
  } else {
    builder.icosphere(region, {0, 0, 0}, radius);
  }
  return builder;
}

/// A box with a cylindrical hole along z from the top face down to `depth` (through when
/// depth >= box height; otherwise with a flat bottom).
PatchBuilder box_with_hole_of_depth(const ShapeOptions& options, double depth) {
  PatchBuilder builder(options, diagonal(kBoxHi - kBoxLo));
  const double radius = 0.3;
  const double bottom_z = std::max(kBoxHi[2] - depth, kBoxLo[2]);
  const bool through = bottom_z <= kBoxLo[2];
  const CircleFrame frame = CircleFrame::around({0.15, 0, bottom_z}, kUp);
  const int count = builder.arc_segments(radius, 2 * kPi);
  const Ring rim_bottom = builder.circle(frame, radius, 0, count);
  const Ring rim_top = builder.circle(frame, radius, kBoxHi[2] - bottom_z, count);
  const auto c = box_corners(builder, kBoxLo, kBoxHi);
  if (through) {
    box_faces(builder, c, {rim_bottom.vertices}, {rim_top.vertices});
  } else {
    box_faces(builder, c, {}, {rim_top.vertices});
  }
  builder.cylinder_patch(builder.add_cylinder(frame, radius, true), frame, radius, 0,
                         kBoxHi[2] - bottom_z, rim_bottom, rim_top);
  if (!through) disc_face(builder, rim_bottom, kUp);  // the material is below the hole's floor
  return builder;
}

PatchBuilder box_with_hole(const ShapeOptions& options) {
  return box_with_hole_of_depth(options, kBoxHi[2] - kBoxLo[2]);
}

PatchBuilder box_with_blind_hole(const ShapeOptions& options) {
  return box_with_hole_of_depth(options, 0.5);
}

PatchBuilder box_with_boss(const ShapeOptions& options) {
  const Vec3 lo{-0.8, -0.6, -0.3}, hi{0.8, 0.6, 0.3};
  const double radius = 0.35, boss_height = 0.4;
  PatchBuilder builder(options,
                       diagonal({hi[0] - lo[0], hi[1] - lo[1], hi[2] + boss_height - lo[2]}));
  const CircleFrame frame = CircleFrame::around({-0.2, 0.05, hi[2]}, kUp);
  const int count = builder.arc_segments(radius, 2 * kPi);
  const Ring foot = builder.circle(frame, radius, 0, count);
  const Ring rim = builder.circle(frame, radius, boss_height, count);
  box_faces(builder, box_corners(builder, lo, hi), {}, {foot.vertices});
  builder.cylinder_patch(builder.add_cylinder(frame, radius, false), frame, radius, 0, boss_height,
                         foot, rim);
  disc_face(builder, rim, kUp);
  return builder;
}

PatchBuilder box_with_dome(const ShapeOptions& options) {
  const Vec3 lo{-0.8, -0.6, -0.3}, hi{0.8, 0.6, 0.3};
  // A cap of a sphere of radius 0.6 cut by the top face along a circle of radius 0.45: it meets
  // the face at an angle (not tangentially), as a real dome feature would.
  const double sphere_radius = 0.6, base_radius = 0.45;
  const double centre_depth = std::sqrt(sphere_radius * sphere_radius - base_radius * base_radius);
  const Vec3 centre{0.1, 0, hi[2] - centre_depth};
  PatchBuilder builder(options,
                       diagonal({hi[0] - lo[0], hi[1] - lo[1], centre[2] + sphere_radius - lo[2]}));
  const CircleFrame frame = CircleFrame::around(centre, kUp);
  const double base_polar = std::asin(base_radius / sphere_radius);
  const Ring base = builder.latitude(frame, sphere_radius, base_polar,
                                     builder.arc_segments(base_radius, 2 * kPi));
  box_faces(builder, box_corners(builder, lo, hi), {}, {base.vertices});
  const Ring top = builder.pole(frame.sphere_point(sphere_radius, 0, 0));
  builder.sphere_patch(builder.add_sphere(centre, sphere_radius, false), frame, sphere_radius, 0,
                       base_polar, top, base);
  return builder;
}

PatchBuilder stepped_block(const ShapeOptions& options) {
  // L-shaped profile in the xz plane, counter-clockwise seen from -y, extruded along y.
  const std::array<std::array<double, 2>, 6> profile{
      {{0, 0}, {1.6, 0}, {1.6, 0.5}, {0.8, 0.5}, {0.8, 1.0}, {0, 1.0}}};
  const double depth = 1.0;
  PatchBuilder builder(options, diagonal({1.6, depth, 1.0}));
  std::vector<std::uint32_t> front, back;
  for (const auto& [x, z] : profile) {
    front.push_back(builder.add_vertex({x, 0, z}));
    back.push_back(builder.add_vertex({x, depth, z}));
  }
  plane_face(builder, front, {0, -1, 0});
  plane_face(builder, back, {0, 1, 0});
  for (std::size_t k = 0; k < profile.size(); ++k) {
    const std::size_t next = (k + 1) % profile.size();
    const double dx = profile[next][0] - profile[k][0], dz = profile[next][1] - profile[k][1];
    plane_face(builder, {front[k], front[next], back[next], back[k]}, {dz, 0, -dx});
  }
  return builder;
}

PatchBuilder cylinder_with_sphere_cap(const ShapeOptions& options) {
  const double radius = 0.5, height = 1.0;
  PatchBuilder builder(options, diagonal({2 * radius, 2 * radius, height + radius}));
  const CircleFrame cylinder_frame = CircleFrame::around({0, 0, -height / 2}, kUp);
  const CircleFrame sphere_frame = CircleFrame::around({0, 0, height / 2}, kUp);
  const int count = builder.arc_segments(radius, 2 * kPi);
  const Ring bottom = builder.circle(cylinder_frame, radius, 0, count);
  const Ring equator = builder.circle(cylinder_frame, radius, height, count);
  builder.cylinder_patch(builder.add_cylinder(cylinder_frame, radius, false), cylinder_frame,
                         radius, 0, height, bottom, equator);
  const Ring top = builder.pole(sphere_frame.sphere_point(radius, 0, 0));
  builder.sphere_patch(builder.add_sphere(sphere_frame.centre, radius, false), sphere_frame, radius,
                       0, kPi / 2, top, equator);
  disc_face(builder, bottom, {0, 0, -1});
  return builder;
}

/// A capped cylinder (radius 0.5, height 1.2) whose top edge is chamfered at 45 degrees: the
/// chamfer is a cone with its apex above the top, on the axis.
PatchBuilder chamfered_cylinder(const ShapeOptions& options) {
  const double radius = 0.5, height = 1.2, chamfer = 0.1;
  PatchBuilder builder(options, diagonal({2 * radius, 2 * radius, height}));
  const CircleFrame frame = CircleFrame::around({0, 0, -height / 2}, kUp);
  const int count = builder.arc_segments(radius, 2 * kPi);
  const double shoulder = height - chamfer;
  const Ring bottom = builder.circle(frame, radius, 0, count);
  const Ring edge = builder.circle(frame, radius, shoulder, count);
  const Ring top = builder.circle(frame, radius - chamfer, height,
                                  builder.arc_segments(radius - chamfer, 2 * kPi));
  builder.cylinder_patch(builder.add_cylinder(frame, radius, false), frame, radius, 0, shoulder,
                         bottom, edge);
  const Vec3 apex = frame.cylinder_point(0, shoulder + radius, 0);
  builder.revolution_patch(
      builder.add_cone(apex, {0, 0, -1}, kPi / 4, false), frame,
      [&](double s) {
        return std::pair{radius - s * chamfer, shoulder + s * chamfer};
      },
      chamfer * std::sqrt(2.0), 1, edge, top);
  disc_face(builder, bottom, {0, 0, -1});
  disc_face(builder, top, kUp);
  return builder;
}

/// A capped cylinder (radius 0.5, height 1.2) whose top edge is rounded by a fillet of radius
/// 0.15: a quarter of a torus, tangent to the side and to the top.
PatchBuilder filleted_cylinder(const ShapeOptions& options) {
  const double radius = 0.5, height = 1.2, fillet = 0.15;
  PatchBuilder builder(options, diagonal({2 * radius, 2 * radius, height}));
  const CircleFrame frame = CircleFrame::around({0, 0, -height / 2}, kUp);
  const int count = builder.arc_segments(radius, 2 * kPi);
  const double shoulder = height - fillet, inner = radius - fillet;
  const Ring bottom = builder.circle(frame, radius, 0, count);
  const Ring edge = builder.circle(frame, radius, shoulder, count);
  const Ring top = builder.circle(frame, inner, height, builder.arc_segments(inner, 2 * kPi));
  builder.cylinder_patch(builder.add_cylinder(frame, radius, false), frame, radius, 0, shoulder,
                         bottom, edge);
  const double quarter = kPi / 2;
  builder.revolution_patch(
      builder.add_torus(frame.cylinder_point(0, shoulder, 0), kUp, inner, fillet, false), frame,
      [&](double s) {
        return std::pair{inner + fillet * std::cos(s * quarter),
                         shoulder + fillet * std::sin(s * quarter)};
      },
      fillet * quarter, builder.arc_segments(fillet, quarter), edge, top);
  disc_face(builder, bottom, {0, 0, -1});
  disc_face(builder, top, kUp);
  return builder;
}

/// The box with a through-hole of radius 0.2 whose top is countersunk at 90 degrees (a cone of
/// half-angle 45 degrees from radius 0.35 at the top face).
PatchBuilder box_with_countersink(const ShapeOptions& options) {
  PatchBuilder builder(options, diagonal(kBoxHi - kBoxLo));
  const double radius = 0.2, countersink = 0.35;
  const double depth = countersink - radius;  // 45 degrees
  const double thickness = kBoxHi[2] - kBoxLo[2];
  const CircleFrame frame = CircleFrame::around({0.15, 0, kBoxLo[2]}, kUp);
  const int count = builder.arc_segments(radius, 2 * kPi);
  const Ring rim_bottom = builder.circle(frame, radius, 0, count);
  const Ring rim_top = builder.circle(frame, radius, thickness - depth, count);
  const Ring mouth =
      builder.circle(frame, countersink, thickness, builder.arc_segments(countersink, 2 * kPi));
  box_faces(builder, box_corners(builder, kBoxLo, kBoxHi), {rim_bottom.vertices}, {mouth.vertices});
  builder.cylinder_patch(builder.add_cylinder(frame, radius, true), frame, radius, 0,
                         thickness - depth, rim_bottom, rim_top);
  const Vec3 apex = frame.cylinder_point(0, thickness - countersink, 0);
  builder.revolution_patch(
      builder.add_cone(apex, kUp, kPi / 4, true), frame,
      [&](double s) {
        return std::pair{radius + s * depth, thickness - depth + s * depth};
      },
      depth * std::sqrt(2.0), 1, rim_top, mouth);
  return builder;
}

}  // namespace

const std::vector<CatalogueEntry>& catalogue() {
  static const std::vector<CatalogueEntry> entries{
      {"box", box},
      {"slanted_box", slanted_box},
      {"capped_cylinder", capped_cylinder},
      {"sphere", sphere},
      {"box_with_hole", box_with_hole},
      {"box_with_blind_hole", box_with_blind_hole},
      {"box_with_boss", box_with_boss},
      {"box_with_dome", box_with_dome},
      {"stepped_block", stepped_block},
      {"cylinder_with_sphere_cap", cylinder_with_sphere_cap},
      {"chamfered_cylinder", chamfered_cylinder},
      {"filleted_cylinder", filleted_cylinder},
      {"box_with_countersink", box_with_countersink},
  };
  return entries;
}

}  // namespace primseg::shape_detail
