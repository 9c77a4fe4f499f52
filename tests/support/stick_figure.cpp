#include "support/stick_figure.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "shape_generator/planar_triangulation.hpp"
#include "shape_generator/vector_math.hpp"

namespace primseg::testing {
namespace {

using namespace shape_detail;
constexpr double kPi = std::numbers::pi;

// Dimensions (torso radius 1).
constexpr double kTorsoHeight = 4.0;
constexpr double kHeadRadius = 1.25;
constexpr double kShoulderHeight = 3.2;
constexpr double kElbowDistance = 2.4;  // from the torso axis
constexpr double kForearmLength = 1.6;  // from the elbow centre
constexpr double kElbowBend = 60 * kPi / 180;
constexpr double kHipHeight = 1.7;
constexpr double kLegDescent = 40 * kPi / 180;  // below horizontal
constexpr double kLegLength = 2.8;              // from the torso axis
// The torso's seam (angle of its unrolled parameter domain's edges), away from the limbs at 0, pi.
constexpr double kSeam = kPi / 2;

struct Builder {
  Mesh mesh;
  std::vector<std::uint32_t> part_of_triangle;

  std::uint32_t vertex(const Vec3& p) {
    mesh.positions.push_back(p);
    return static_cast<std::uint32_t>(mesh.positions.size() - 1);
  }
  void triangle(std::uint32_t part, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    mesh.triangles.push_back({a, b, c});
    part_of_triangle.push_back(part);
  }
  // Quads between consecutive rings of equal size, closed around; outward when the rings go
  // along the surface's "s" direction and their vertices turn by the right-hand rule about it.
  void strips(std::uint32_t part, const std::vector<std::vector<std::uint32_t>>& rings) {
    for (std::size_t i = 0; i + 1 < rings.size(); ++i) {
      const std::size_t m = rings[i].size();
      for (std::size_t k = 0; k < m; ++k) {
        const std::size_t next = (k + 1) % m;
        triangle(part, rings[i][k], rings[i][next], rings[i + 1][k]);
        triangle(part, rings[i][next], rings[i + 1][next], rings[i + 1][k]);
      }
    }
  }
};

// A limb: a straight cylinder from the torso's surface, whose axis passes through `origin` on
// the torso's axis with unit direction `direction`.
struct Limb {
  Vec3 origin, direction, e1, e2;
  double radius;

  Vec3 generator_point(double phi) const {
    return origin + radius * (std::cos(phi) * e1 + std::sin(phi) * e2);
  }
  // Distance along the axis direction where generator phi leaves the torso x² + y² = 1.
  double exit(double phi) const {
    const Vec3 p = generator_point(phi);
    const double a = direction[0] * direction[0] + direction[1] * direction[1];
    const double b = 2 * (p[0] * direction[0] + p[1] * direction[1]);
    const double c = p[0] * p[0] + p[1] * p[1] - 1;
    return (-b + std::sqrt(b * b - 4 * a * c)) / (2 * a);
  }
};

Limb make_limb(const Vec3& origin, const Vec3& direction, double radius) {
  Limb limb{origin, direction, {0, 0, 0}, {0, 0, 0}, radius};
  limb.e1 = normalized(cross(direction, Vec3{0, 1, 0}));  // in the x-z plane
  limb.e2 = cross(direction, limb.e1);
  return limb;
}

}  // namespace

std::uint32_t StickFigure::part(const std::string& name) const {
  const auto it = std::find(parts.begin(), parts.end(), name);
  if (it == parts.end()) throw std::invalid_argument("no part " + name);
  return static_cast<std::uint32_t>(it - parts.begin());
}

StickFigure make_stick_figure(double edge) {
  StickFigure figure;
  figure.parts = {"torso",        "head",          "upper_arm_left", "upper_arm_right",
                  "forearm_left", "forearm_right", "leg_left",       "leg_right"};
  figure.attachment.assign(figure.parts.size(), Vec3{0, 0, 0});
  figure.axis.assign(figure.parts.size(), Vec3{0, 0, 1});
  Builder b;
  auto count = [&](double length) {
    return std::max(3, static_cast<int>(std::ceil(length / edge)));
  };

  const int ring_count = count(2 * kPi);  // around the torso, also the head's rings
  // Torso hole loops in the unrolled domain (x = angle from the seam, y = z), with their vertex
  // ids.
  std::vector<std::vector<Point2>> loops(1);
  std::vector<std::vector<std::uint32_t>> loop_vertices(1);
  auto domain = [](const Vec3& p) {
    double angle = std::atan2(p[1], p[0]) - kSeam;
    while (angle < 0) angle += 2 * kPi;
    return Point2{angle, p[2]};
  };

  auto add_hole = [&](const std::vector<std::uint32_t>& ring) {
    loops.emplace_back();
    loop_vertices.push_back(ring);
    for (const std::uint32_t v : ring) loops.back().push_back(domain(b.mesh.positions[v]));
  };

  for (int side = 0; side < 2; ++side) {  // 0: left (-x), 1: right (+x)
    const double sx = side == 0 ? -1 : 1;
    // Arm: upper arm along ±x, forearm bent down by kElbowBend, mitred on the bisecting plane.
    const Limb upper = make_limb({0, 0, kShoulderHeight}, {sx, 0, 0}, figure.arm_radius);
    const Vec3 elbow{sx * kElbowDistance, 0, kShoulderHeight};
    const Vec3 fore_dir{sx * std::cos(kElbowBend), 0, -std::sin(kElbowBend)};
    const Vec3 mitre_normal = normalized(upper.direction + fore_dir);
    const int around = count(2 * kPi * figure.arm_radius);
    std::vector<double> phis;
    for (int k = 0; k < around; ++k) phis.push_back(2 * kPi * k / around);
    std::vector<std::vector<std::uint32_t>> rings;
    std::vector<double> s0(around), s1(around);
    for (int k = 0; k < around; ++k) {
      const Vec3 p = upper.generator_point(phis[k]);
      s0[k] = upper.exit(phis[k]);
      s1[k] = dot(elbow - p, mitre_normal) / dot(upper.direction, mitre_normal);
    }
    const int upper_bands = count(kElbowDistance - 1);
    for (int i = 0; i <= upper_bands; ++i) {
      std::vector<std::uint32_t> ring;
      for (int k = 0; k < around; ++k) {
        const double s = s0[k] + (s1[k] - s0[k]) * i / upper_bands;
        ring.push_back(b.vertex(upper.generator_point(phis[k]) + s * upper.direction));
      }
      rings.push_back(ring);
    }
    const std::uint32_t upper_part = figure.part(side == 0 ? "upper_arm_left" : "upper_arm_right");
    const std::uint32_t fore_part = figure.part(side == 0 ? "forearm_left" : "forearm_right");
    b.strips(upper_part, rings);
    figure.attachment[upper_part] = {sx, 0, kShoulderHeight};
    figure.axis[upper_part] = upper.direction;
    figure.axis[fore_part] = fore_dir;
    figure.elbow[side] = elbow;
    add_hole(rings.front());
    // Forearm: generators continue from the mitre along fore_dir to a plane end.
    std::vector<std::vector<std::uint32_t>> fore_rings{rings.back()};
    const int fore_bands = count(kForearmLength);
    for (int i = 1; i <= fore_bands; ++i) {
      std::vector<std::uint32_t> ring;
      for (int k = 0; k < around; ++k) {
        const Vec3 q = b.mesh.positions[rings.back()[k]];
        const double u_end = kForearmLength - dot(q - elbow, fore_dir);
        ring.push_back(b.vertex(q + (u_end * i / fore_bands) * fore_dir));
      }
      fore_rings.push_back(ring);
    }
    b.strips(fore_part, fore_rings);

    // Leg: down and out, straight, open at its end.
    const Vec3 leg_dir{sx * std::cos(kLegDescent), 0, -std::sin(kLegDescent)};
    const Limb leg = make_limb({0, 0, kHipHeight}, leg_dir, figure.leg_radius);
    const int leg_around = count(2 * kPi * figure.leg_radius);
    std::vector<std::vector<std::uint32_t>> leg_rings;
    const int leg_bands = count(kLegLength - 1);
    for (int i = 0; i <= leg_bands; ++i) {
      std::vector<std::uint32_t> ring;
      for (int k = 0; k < leg_around; ++k) {
        const double phi = 2 * kPi * k / leg_around;
        const double s0_leg = leg.exit(phi);
        const double s = s0_leg + (kLegLength - s0_leg) * i / leg_bands;
        ring.push_back(b.vertex(leg.generator_point(phi) + s * leg.direction));
      }
      leg_rings.push_back(ring);
    }
    const std::uint32_t leg_part = figure.part(side == 0 ? "leg_left" : "leg_right");
    b.strips(leg_part, leg_rings);
    figure.axis[leg_part] = leg_dir;
    figure.attachment[leg_part] = Vec3{0, 0, kHipHeight} + (1 / std::cos(kLegDescent)) * leg_dir;
    add_hole(leg_rings.front());
  }

  // Torso boundary: bottom (z = 0, open), seam, top (shared with the head), seam again.
  std::vector<std::uint32_t> bottom, top;
  for (int k = 0; k < ring_count; ++k) {
    const double angle = kSeam + 2 * kPi * k / ring_count;
    bottom.push_back(b.vertex({std::cos(angle), std::sin(angle), 0}));
  }
  for (int k = 0; k < ring_count; ++k) {
    const double angle = kSeam + 2 * kPi * k / ring_count;
    top.push_back(b.vertex({std::cos(angle), std::sin(angle), kTorsoHeight}));
  }
  const int seam_count = count(kTorsoHeight);
  std::vector<std::uint32_t> seam{bottom[0]};
  for (int i = 1; i < seam_count; ++i)
    seam.push_back(b.vertex({std::cos(kSeam), std::sin(kSeam), kTorsoHeight * i / seam_count}));
  seam.push_back(top[0]);
  // Outer loop, counter-clockwise in the domain: bottom left to right, right seam up, top right
  // to left, left seam down. Both seams are the same vertices.
  std::vector<Point2>& outer = loops[0];
  std::vector<std::uint32_t>& outer_ids = loop_vertices[0];
  for (int k = 0; k < ring_count; ++k) {
    outer.push_back({2 * kPi * k / ring_count, 0});
    outer_ids.push_back(bottom[k]);
  }
  for (int i = 0; i < seam_count; ++i) {
    outer.push_back({2 * kPi, kTorsoHeight * i / seam_count});
    outer_ids.push_back(seam[i]);
  }
  for (int k = ring_count; k > 0; --k) {
    outer.push_back({2 * kPi * k / ring_count, kTorsoHeight});
    outer_ids.push_back(k == ring_count ? top[0] : top[k]);
  }
  for (int i = seam_count; i > 0; --i) {
    outer.push_back({0, kTorsoHeight * i / seam_count});
    outer_ids.push_back(seam[i]);
  }
  const PlanarTriangulation torso = triangulate_planar_domain(loops, edge);
  std::vector<std::uint32_t> torso_vertex;
  for (const auto& ids : loop_vertices)
    torso_vertex.insert(torso_vertex.end(), ids.begin(), ids.end());
  for (const Point2& p : torso.interior_points) {
    const double angle = kSeam + p.x;
    torso_vertex.push_back(b.vertex({std::cos(angle), std::sin(angle), p.y}));
  }
  const std::uint32_t torso_part = figure.part("torso");
  for (const auto& t : torso.triangles)
    b.triangle(torso_part, torso_vertex[t[0]], torso_vertex[t[1]], torso_vertex[t[2]]);

  // Head: the sphere through the torso's top circle, from that circle up to its pole.
  const double centre_height = kTorsoHeight + std::sqrt(kHeadRadius * kHeadRadius - 1);
  const double polar_end = kPi - std::asin(1 / kHeadRadius);
  const int head_bands = count(kHeadRadius * polar_end);
  std::vector<std::vector<std::uint32_t>> head_rings;
  for (int i = 1; i < head_bands; ++i) {
    const double polar = polar_end * i / head_bands;
    std::vector<std::uint32_t> ring;
    for (int k = 0; k < ring_count; ++k) {
      const double angle = kSeam + 2 * kPi * k / ring_count;
      ring.push_back(b.vertex({kHeadRadius * std::sin(polar) * std::cos(angle),
                               kHeadRadius * std::sin(polar) * std::sin(angle),
                               centre_height + kHeadRadius * std::cos(polar)}));
    }
    head_rings.push_back(ring);
  }
  head_rings.push_back(top);
  const std::uint32_t head_part = figure.part("head");
  const std::uint32_t pole = b.vertex({0, 0, centre_height + kHeadRadius});
  for (int k = 0; k < ring_count; ++k)
    b.triangle(head_part, pole, head_rings[0][k], head_rings[0][(k + 1) % ring_count]);
  // Rings go down (polar angle up) and turn counter-clockwise about z: outward is ring k, then
  // the next ring, then k + 1.
  for (std::size_t i = 0; i + 1 < head_rings.size(); ++i)
    for (int k = 0; k < ring_count; ++k) {
      const int next = (k + 1) % ring_count;
      b.triangle(head_part, head_rings[i][k], head_rings[i + 1][k], head_rings[i][next]);
      b.triangle(head_part, head_rings[i][next], head_rings[i + 1][k], head_rings[i + 1][next]);
    }

  figure.mesh = Mesh::from_triangles(std::move(b.mesh.positions), std::move(b.mesh.triangles));
  figure.part_of_face = std::move(b.part_of_triangle);
  return figure;
}

}  // namespace primseg::testing
