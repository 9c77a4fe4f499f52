#include "patch_builder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "planar_triangulation.hpp"
#include "vector_math.hpp"

namespace primseg::shape_detail {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
// Row spacing of a lattice of equilateral triangles of unit edge.
const double kRowSpacing = std::sqrt(3.0) / 2;

/// a mod 2 pi, in [0, 2 pi).
double wrap_turn(double a) {
  const double r = std::fmod(a, kTwoPi);
  return r < 0 ? r + kTwoPi : r;
}
/// a mod 2 pi, in [-pi, pi).
double wrap_half_turn(double a) {
  return wrap_turn(a + std::numbers::pi) - std::numbers::pi;
}

int at_least(int minimum, double value) {
  return std::max(minimum, static_cast<int>(std::ceil(value - 1e-9)));
}

}  // namespace

Vec3 RegionSurface::outward_normal(const Vec3& x) const {
  switch (primitive.type) {
    case PrimitiveType::Plane:
      return primitive.axis;
    case PrimitiveType::Cylinder: {
      const Vec3 d = x - primitive.point;
      return outward_sign * normalized(d - dot(d, primitive.axis) * primitive.axis);
    }
    case PrimitiveType::Sphere:
      return outward_sign * normalized(x - primitive.point);
    case PrimitiveType::Cone: {
      const Vec3 d = x - primitive.point;
      const Vec3 radial = normalized(d - dot(d, primitive.axis) * primitive.axis);
      return outward_sign * (std::cos(primitive.half_angle) * radial -
                             std::sin(primitive.half_angle) * primitive.axis);
    }
    case PrimitiveType::Torus: {
      const Vec3 d = x - primitive.point;
      const Vec3 radial = normalized(d - dot(d, primitive.axis) * primitive.axis);
      return outward_sign * normalized(x - (primitive.point + primitive.radius * radial));
    }
    default:
      throw std::logic_error("shape generator: unsupported region surface");
  }
}

CircleFrame CircleFrame::around(const Vec3& centre, const Vec3& axis) {
  const Vec3 unit_axis = normalized(axis);
  const Vec3 x_dir = any_perpendicular(unit_axis);
  return {centre, unit_axis, x_dir, cross(unit_axis, x_dir)};
}

Vec3 CircleFrame::cylinder_point(double radius, double height, double angle) const {
  return centre + height * axis + (radius * std::cos(angle)) * x_dir +
         (radius * std::sin(angle)) * y_dir;
}

Vec3 CircleFrame::sphere_point(double radius, double polar, double angle) const {
  const double ring_radius = radius * std::sin(polar);
  return centre + (radius * std::cos(polar)) * axis + (ring_radius * std::cos(angle)) * x_dir +
         (ring_radius * std::sin(angle)) * y_dir;
}

PatchBuilder::PatchBuilder(const ShapeOptions& options, double diagonal)
    : cad_(options.tessellation == Tessellation::Cad),
      segments_(options.segments),
      target_edge_(options.edge_length * diagonal) {}

std::uint32_t PatchBuilder::add_vertex(const Vec3& p) {
  positions_.push_back(p);
  return static_cast<std::uint32_t>(positions_.size() - 1);
}

std::uint32_t PatchBuilder::add_plane(const Vec3& point, const Vec3& outward_normal) {
  RegionSurface surface;
  surface.primitive.type = PrimitiveType::Plane;
  surface.primitive.point = point;
  surface.primitive.axis = normalized(outward_normal);
  regions_.push_back(surface);
  return static_cast<std::uint32_t>(regions_.size() - 1);
}

std::uint32_t PatchBuilder::add_cylinder(const CircleFrame& frame, double radius, bool hole) {
  RegionSurface surface;
  surface.primitive.type = PrimitiveType::Cylinder;
  surface.primitive.point = frame.centre;
  surface.primitive.axis = frame.axis;
  surface.primitive.radius = radius;
  surface.outward_sign = hole ? -1 : 1;
  regions_.push_back(surface);
  return static_cast<std::uint32_t>(regions_.size() - 1);
}

std::uint32_t PatchBuilder::add_sphere(const Vec3& centre, double radius, bool hole) {
  RegionSurface surface;
  surface.primitive.type = PrimitiveType::Sphere;
  surface.primitive.point = centre;
  surface.primitive.radius = radius;
  surface.outward_sign = hole ? -1 : 1;
  regions_.push_back(surface);
  return static_cast<std::uint32_t>(regions_.size() - 1);
}

std::uint32_t PatchBuilder::add_cone(const Vec3& apex, const Vec3& axis, double half_angle,
                                     bool hole) {
  RegionSurface surface;
  surface.primitive.type = PrimitiveType::Cone;
  surface.primitive.point = apex;
  surface.primitive.axis = normalized(axis);
  surface.primitive.half_angle = half_angle;
  surface.outward_sign = hole ? -1 : 1;
  regions_.push_back(surface);
  return static_cast<std::uint32_t>(regions_.size() - 1);
}

std::uint32_t PatchBuilder::add_torus(const Vec3& centre, const Vec3& axis, double major_radius,
                                      double minor_radius, bool hole) {
  RegionSurface surface;
  surface.primitive.type = PrimitiveType::Torus;
  surface.primitive.point = centre;
  surface.primitive.axis = normalized(axis);
  surface.primitive.radius = major_radius;
  surface.primitive.minor_radius = minor_radius;
  surface.outward_sign = hole ? -1 : 1;
  regions_.push_back(surface);
  return static_cast<std::uint32_t>(regions_.size() - 1);
}

int PatchBuilder::uniform_bands(double length) const {
  return std::max(1, static_cast<int>(std::lround(length / (kRowSpacing * target_edge_))));
}

std::vector<std::uint32_t> PatchBuilder::straight_edge(std::uint32_t from, std::uint32_t to) {
  const auto key = std::minmax(from, to);
  auto found = edges_.find(key);
  if (found == edges_.end()) {
    const Vec3 a = positions_[key.first], b = positions_[key.second];
    const int count = cad_ ? 1 : at_least(1, norm(b - a) / target_edge_);
    std::vector<std::uint32_t> samples{key.first};
    for (int k = 1; k < count; ++k) {
      samples.push_back(add_vertex(a + (static_cast<double>(k) / count) * (b - a)));
    }
    samples.push_back(key.second);
    found = edges_.emplace(key, std::move(samples)).first;
  }
  std::vector<std::uint32_t> samples = found->second;
  if (samples.front() != from) std::reverse(samples.begin(), samples.end());
  return samples;
}

std::vector<std::uint32_t> PatchBuilder::polygon_loop(const std::vector<std::uint32_t>& corners) {
  std::vector<std::uint32_t> loop;
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const auto edge = straight_edge(corners[k], corners[(k + 1) % corners.size()]);
    loop.insert(loop.end(), edge.begin(), edge.end() - 1);
  }
  return loop;
}

int PatchBuilder::arc_segments(double radius, double angle) const {
  const bool full_turn = angle >= kTwoPi - 1e-12;
  if (cad_) return at_least(full_turn ? 3 : 1, segments_ * angle / kTwoPi);
  return at_least(full_turn ? 6 : 1, radius * angle / target_edge_);
}

Ring PatchBuilder::circle(const CircleFrame& frame, double radius, double height, int count,
                          double phase) {
  Ring ring;
  for (int k = 0; k < count; ++k) {
    const double angle = kTwoPi * (k + phase) / count;
    ring.vertices.push_back(add_vertex(frame.cylinder_point(radius, height, angle)));
    ring.angles.push_back(angle);
  }
  return ring;
}

Ring PatchBuilder::latitude(const CircleFrame& frame, double radius, double polar, int count,
                            double phase) {
  Ring ring;
  for (int k = 0; k < count; ++k) {
    const double angle = kTwoPi * (k + phase) / count;
    ring.vertices.push_back(add_vertex(frame.sphere_point(radius, polar, angle)));
    ring.angles.push_back(angle);
  }
  return ring;
}

Ring PatchBuilder::pole(const Vec3& p) {
  Ring ring;
  ring.vertices.push_back(add_vertex(p));
  return ring;
}

void PatchBuilder::planar_patch(std::uint32_t region,
                                const std::vector<std::vector<std::uint32_t>>& loops) {
  const Primitive& plane = regions_[region].primitive;
  const Vec3 origin = positions_[loops[0][0]];
  // The first outer edge gives the in-plane x axis, so that lattice rows follow it.
  Vec3 first_edge = positions_[loops[0][1]] - origin;
  first_edge = first_edge - dot(first_edge, plane.axis) * plane.axis;
  const Vec3 e1 = normalized(first_edge), e2 = cross(plane.axis, e1);

  std::vector<std::vector<Point2>> loops2d;
  std::vector<std::uint32_t> boundary_vertices;
  for (const auto& loop : loops) {
    auto& loop2d = loops2d.emplace_back();
    for (std::uint32_t v : loop) {
      const Vec3 d = positions_[v] - origin;
      loop2d.push_back({dot(d, e1), dot(d, e2)});
      boundary_vertices.push_back(v);
    }
  }
  const PlanarTriangulation result = triangulate_planar_domain(loops2d, cad_ ? 0.0 : target_edge_);
  std::vector<std::uint32_t> vertex_of = boundary_vertices;
  for (const Point2& p : result.interior_points) {
    vertex_of.push_back(add_vertex(origin + p.x * e1 + p.y * e2));
  }
  for (const auto& t : result.triangles)
    emit(region, vertex_of[t[0]], vertex_of[t[1]], vertex_of[t[2]]);
}

void PatchBuilder::cylinder_patch(std::uint32_t region, const CircleFrame& frame, double radius,
                                  double bottom_height, double top_height, const Ring& bottom,
                                  const Ring& top) {
  std::vector<Ring> rings{bottom};
  if (!cad_) {
    const double length = top_height - bottom_height;
    const int bands =
        std::max(1, static_cast<int>(std::lround(length / (kRowSpacing * target_edge_))));
    const int count = arc_segments(radius, kTwoPi);
    for (int k = 1; k < bands; ++k) {
      // Shifting every other ring by half a step turns the quads into near-equilateral pairs.
      rings.push_back(
          circle(frame, radius, bottom_height + length * k / bands, count, k % 2 == 1 ? 0.5 : 0.0));
    }
  }
  rings.push_back(top);
  ring_strips(region, rings);
}

void PatchBuilder::sphere_patch(std::uint32_t region, const CircleFrame& frame, double radius,
                                double polar_start, double polar_end, const Ring& start,
                                const Ring& end) {
  const double span = polar_end - polar_start;
  const int bands =
      cad_ ? at_least(1, span * segments_ / kTwoPi)
           : std::max(1,
                      static_cast<int>(std::lround(radius * span / (kRowSpacing * target_edge_))));
  std::vector<Ring> rings{start};
  for (int k = 1; k < bands; ++k) {
    const double polar = polar_start + span * k / bands;
    const int count = arc_segments(radius * std::sin(polar), kTwoPi);
    rings.push_back(latitude(frame, radius, polar, count, (!cad_ && k % 2 == 1) ? 0.5 : 0.0));
  }
  rings.push_back(end);
  ring_strips(region, rings);
}

void PatchBuilder::icosphere(std::uint32_t region, const Vec3& centre, double radius) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  const std::array<Vec3, 12> corners{{{-1, t, 0},
                                      {1, t, 0},
                                      {-1, -t, 0},
                                      {1, -t, 0},
                                      {0, -1, t},
                                      {0, 1, t},
                                      {0, -1, -t},
                                      {0, 1, -t},
                                      {t, 0, -1},
                                      {t, 0, 1},
                                      {-t, 0, -1},
                                      {-t, 0, 1}}};
  const std::array<std::array<int, 3>, 20> faces{
      {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
       {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
       {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}}};
  // Icosahedron edge / circumradius = 1.05, and projection stretches the middle of each face:
  // this frequency gives edges of 0.8 to 1.1 target lengths.
  const int frequency = std::max(1, static_cast<int>(std::lround(1.25 * radius / target_edge_)));
  // A lattice point is named by its weights on the icosahedron corners sorted by corner, so that
  // a point on an edge shared by two faces is created once and computed identically.
  std::map<std::array<int, 6>, std::uint32_t> vertex_of_key;
  auto lattice_vertex = [&](const std::array<int, 3>& face, int i, int j) {
    std::array<std::pair<int, int>, 3> weights{
        {{face[0], i}, {face[1], j}, {face[2], frequency - i - j}}};
    std::sort(weights.begin(), weights.end());
    std::array<int, 6> key{-1, 0, -1, 0, -1, 0};
    Vec3 direction{0, 0, 0};
    std::size_t slot = 0;
    for (const auto& [corner, weight] : weights) {
      if (weight == 0) continue;
      key[2 * slot] = corner, key[2 * slot + 1] = weight, ++slot;
      direction = direction + static_cast<double>(weight) * corners[corner];
    }
    auto [it, inserted] = vertex_of_key.try_emplace(key, 0);
    if (inserted) it->second = add_vertex(centre + radius * normalized(direction));
    return it->second;
  };
  for (const auto& face : faces) {
    for (int i = 0; i < frequency; ++i) {
      for (int j = 0; i + j < frequency; ++j) {
        emit(region, lattice_vertex(face, i, j), lattice_vertex(face, i + 1, j),
             lattice_vertex(face, i, j + 1));
        if (i + j + 2 <= frequency) {
          emit(region, lattice_vertex(face, i + 1, j), lattice_vertex(face, i + 1, j + 1),
               lattice_vertex(face, i, j + 1));
        }
      }
    }
  }
}

void PatchBuilder::ring_strips(std::uint32_t region, const std::vector<Ring>& rings, bool wrap) {
  for (std::size_t k = 0; k + 1 < rings.size(); ++k) zip(region, rings[k], rings[k + 1]);
  if (wrap) zip(region, rings.back(), rings.front());
}

void PatchBuilder::zip(std::uint32_t region, const Ring& lower, const Ring& upper) {
  if (lower.vertices.size() == 1 || upper.vertices.size() == 1) {
    const Ring& ring = lower.vertices.size() == 1 ? upper : lower;
    const std::uint32_t apex = (lower.vertices.size() == 1 ? lower : upper).vertices[0];
    const std::size_t n = ring.vertices.size();
    for (std::size_t k = 0; k + (ring.closed ? 0 : 1) < n; ++k) {
      emit(region, ring.vertices[k], ring.vertices[(k + 1) % n], apex);
    }
    return;
  }
  const std::size_t na = lower.vertices.size(), nb = upper.vertices.size();
  // Unwrapped angles: a[k] for the lower ring from its first vertex, b[k] for the upper ring
  // from its vertex nearest in angle to it; index n closes a closed ring.
  std::vector<double> a(na + 1), b(nb + 1);
  std::size_t b_start = 0;
  if (lower.closed) {
    const double a0 = lower.angles[0];
    for (std::size_t k = 0; k < na; ++k) a[k] = a0 + wrap_turn(lower.angles[k] - a0);
    a[na] = a0 + kTwoPi;
    double best = INFINITY;
    for (std::size_t k = 0; k < nb; ++k) {
      const double gap = std::abs(wrap_half_turn(upper.angles[k] - a0));
      if (gap < best) best = gap, b_start = k;
    }
    const double b0 = a0 + wrap_half_turn(upper.angles[b_start] - a0);
    for (std::size_t k = 0; k < nb; ++k) {
      b[k] = b0 + wrap_turn(upper.angles[(b_start + k) % nb] - upper.angles[b_start]);
    }
    b[nb] = b0 + kTwoPi;
  } else {
    std::copy(lower.angles.begin(), lower.angles.end(), a.begin());
    std::copy(upper.angles.begin(), upper.angles.end(), b.begin());
  }
  const std::size_t a_end = lower.closed ? na : na - 1, b_end = upper.closed ? nb : nb - 1;
  auto lower_vertex = [&](std::size_t k) { return lower.vertices[k % na]; };
  auto upper_vertex = [&](std::size_t k) { return upper.vertices[(b_start + k) % nb]; };
  for (std::size_t i = 0, j = 0; i < a_end || j < b_end;) {
    if (j == b_end || (i < a_end && a[i + 1] <= b[j + 1])) {
      emit(region, lower_vertex(i), lower_vertex(i + 1), upper_vertex(j));
      ++i;
    } else {
      emit(region, lower_vertex(i), upper_vertex(j + 1), upper_vertex(j));
      ++j;
    }
  }
}

void PatchBuilder::emit(std::uint32_t region, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  const Vec3 &pa = positions_[a], &pb = positions_[b], &pc = positions_[c];
  const Vec3 centroid = (1.0 / 3) * (pa + pb + pc);
  const Vec3 normal = cross(pb - pa, pc - pa);
  const RegionSurface& surface = regions_[region];
  // A coarse facet of a torus can have its centroid past the tube's centre circle, where the
  // surface normal points the other way: its vertices (on the surface) are reliable.
  const Vec3 outward =
      surface.primitive.type == PrimitiveType::Torus
          ? surface.outward_normal(pa) + surface.outward_normal(pb) + surface.outward_normal(pc)
          : surface.outward_normal(centroid);
  if (dot(normal, outward) < 0) std::swap(b, c);
  triangles_.push_back({a, b, c});
  triangle_regions_.push_back(region);
}

}  // namespace primseg::shape_detail
