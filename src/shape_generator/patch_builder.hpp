#pragma once
/// @file patch_builder.hpp
/// Assembles a closed triangle mesh from parametric patches (planar polygons with holes, and
/// ring-by-ring curved surfaces) whose boundary curves are sampled once and shared by both
/// adjacent patches, so that the result is conforming.

#include <cstdint>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

#include "primseg/primitive.hpp"
#include "primseg/shape_generator.hpp"

namespace primseg::shape_detail {

/// A curve of mesh vertices at constant v of a curved patch (a circle of latitude, a cylinder's
/// end), with the angle u of each vertex; neighbouring rings are zipped into triangle strips in
/// order of u. A single vertex with no angle is a pole.
struct Ring {
  std::vector<std::uint32_t> vertices;
  std::vector<double> angles;  // radians, increasing, within one turn
  bool closed = true;          // false for an arc (patch not going all around)
};

/// The analytic surface of a region in the build frame, and which side of it is outside the
/// solid.
struct RegionSurface {
  Primitive primitive;  // a plane's axis is its outward normal; curved axes are not canonical yet
  /// +1 when the outside of the solid is away from the axis or centre, -1 for a hole's wall.
  double outward_sign = 1;

  Vec3 outward_normal(const Vec3& x) const;
};

/// An orthonormal frame of a circle, cylinder or sphere: `axis` is the cylinder axis or the
/// sphere's pole direction; angle 0 points along `x_dir`, angle pi/2 along `y_dir`.
struct CircleFrame {
  Vec3 centre;
  Vec3 axis, x_dir, y_dir;

  static CircleFrame around(const Vec3& centre, const Vec3& axis);
  Vec3 cylinder_point(double radius, double height, double angle) const;
  /// Point at polar angle `polar` from the axis and azimuth `angle`.
  Vec3 sphere_point(double radius, double polar, double angle) const;
};

/// Builds a solid patch by patch. Shared boundaries are created once (straight_edge, circle,
/// latitude) and handed to both adjacent patches. Every triangle is oriented by its region's
/// outward normal, so patch code need not care about vertex order.
///
/// New curved surfaces need only a point function and a list of rings: a cone is rings of
/// shrinking radius ending in an apex pole(); a torus is its minor circles joined by
/// ring_strips(region, rings, /*wrap=*/true); a partial surface uses open rings (Ring::closed).
class PatchBuilder {
 public:
  /// `diagonal`: bounding-box diagonal of the shape, the unit of ShapeOptions::edge_length.
  PatchBuilder(const ShapeOptions& options, double diagonal);

  bool cad() const { return cad_; }
  /// Target edge length of the Uniform tessellation, in build units.
  double target_edge() const { return target_edge_; }

  std::uint32_t add_vertex(const Vec3& p);

  std::uint32_t add_plane(const Vec3& point, const Vec3& outward_normal);
  std::uint32_t add_cylinder(const CircleFrame& frame, double radius, bool hole);
  std::uint32_t add_sphere(const Vec3& centre, double radius, bool hole);
  /// A cone with its apex, unit axis from the apex into the cone, and half-angle (radians).
  std::uint32_t add_cone(const Vec3& apex, const Vec3& axis, double half_angle, bool hole);
  /// A torus: centre, unit axis, major and minor radius; `hole`: the solid is inside the tube's
  /// complement (a concave fillet).
  std::uint32_t add_torus(const Vec3& centre, const Vec3& axis, double major_radius,
                          double minor_radius, bool hole);

  /// Vertices from `from` to `to` (both included) along the straight segment between them. The
  /// segment is sampled on the first request; later requests (either direction) reuse it.
  std::vector<std::uint32_t> straight_edge(std::uint32_t from, std::uint32_t to);
  /// Closed loop through `corners` joined by straight edges (last vertex not repeated).
  std::vector<std::uint32_t> polygon_loop(const std::vector<std::uint32_t>& corners);

  /// Number of segments for an arc of `angle` radians and radius `radius`.
  int arc_segments(double radius, double angle) const;
  /// A circle of `count` vertices at height `height` along frame.axis, the first at angle
  /// 2 pi phase / count.
  Ring circle(const CircleFrame& frame, double radius, double height, int count, double phase = 0);
  /// A circle of latitude of a sphere (polar angle strictly between 0 and pi).
  Ring latitude(const CircleFrame& frame, double radius, double polar, int count, double phase = 0);
  Ring pole(const Vec3& p);

  /// Planar region bounded by loops[0] and with holes loops[1..], vertices lying on the plane.
  void planar_patch(std::uint32_t region, const std::vector<std::vector<std::uint32_t>>& loops);
  /// Cylinder between two rings of the same frame at heights `bottom_height` < `top_height`.
  void cylinder_patch(std::uint32_t region, const CircleFrame& frame, double radius,
                      double bottom_height, double top_height, const Ring& bottom, const Ring& top);
  /// Sphere zone between polar angles polar_start < polar_end (0 or pi: `start`/`end` is a pole).
  void sphere_patch(std::uint32_t region, const CircleFrame& frame, double radius,
                    double polar_start, double polar_end, const Ring& start, const Ring& end);
  /// Surface of revolution around frame.axis between two rings of the frame: `profile(s)` gives
  /// (distance from the axis, height along it) for s in [0, 1], s = 0 at `start`; `length` is
  /// the profile's arc length. Cad: `cad_bands` strips; Uniform: bands of the target edge.
  template <typename Profile>
  void revolution_patch(std::uint32_t region, const CircleFrame& frame, Profile&& profile,
                        double length, int cad_bands, const Ring& start, const Ring& end) {
    const int bands = cad_ ? cad_bands : uniform_bands(length);
    std::vector<Ring> rings{start};
    for (int k = 1; k < bands; ++k) {
      const auto [radius, height] = profile(static_cast<double>(k) / bands);
      rings.push_back(circle(frame, radius, height, arc_segments(radius, 2 * std::numbers::pi),
                             (!cad_ && k % 2 == 1) ? 0.5 : 0.0));
    }
    rings.push_back(end);
    ring_strips(region, rings);
  }
  /// Number of ring bands of near-equilateral triangles along a profile of this length.
  int uniform_bands(double length) const;
  /// Whole sphere as a projected subdivided icosahedron.
  void icosphere(std::uint32_t region, const Vec3& centre, double radius);
  /// Strips between consecutive rings (and between the last and first if `wrap`).
  void ring_strips(std::uint32_t region, const std::vector<Ring>& rings, bool wrap = false);

  const std::vector<Vec3>& positions() const { return positions_; }
  const std::vector<Triangle>& triangles() const { return triangles_; }
  const std::vector<std::uint32_t>& triangle_regions() const { return triangle_regions_; }
  const std::vector<RegionSurface>& regions() const { return regions_; }

 private:
  /// Adds a triangle of `region`, flipped if needed to face out of the solid.
  void emit(std::uint32_t region, std::uint32_t a, std::uint32_t b, std::uint32_t c);
  void zip(std::uint32_t region, const Ring& lower, const Ring& upper);

  bool cad_;
  int segments_;
  double target_edge_;
  std::vector<Vec3> positions_;
  std::vector<Triangle> triangles_;
  std::vector<std::uint32_t> triangle_regions_;
  std::vector<RegionSurface> regions_;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> edges_;
};

}  // namespace primseg::shape_detail
