#include "primseg/shape_generator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "catalogue.hpp"
#include "primseg/error.hpp"
#include "random.hpp"
#include "vector_math.hpp"

namespace primseg {
namespace {

using shape_detail::dot;
using shape_detail::normalized;
using shape_detail::PatchBuilder;
using shape_detail::SplitMix64;
// Vec3 is a std::array, so argument-dependent lookup cannot find these (clang-tidy 14 reports
// them unused all the same).
using shape_detail::operator+;  // NOLINT(misc-unused-using-decls)
using shape_detail::operator-;  // NOLINT(misc-unused-using-decls)
using shape_detail::operator*;  // NOLINT(misc-unused-using-decls)

// Independent streams for motion and noise, so that adding noise does not change the motion.
constexpr std::uint64_t kMotionStream = 0x6D6F74696F6E0001ull;
constexpr std::uint64_t kNoiseStream = 0x6E6F697365000002ull;

/// x -> scale * rotation * x + translation.
struct Motion {
  std::array<Vec3, 3> rotation_rows{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  double scale = 1;
  Vec3 translation{0, 0, 0};

  Vec3 rotate(const Vec3& v) const {
    return {dot(rotation_rows[0], v), dot(rotation_rows[1], v), dot(rotation_rows[2], v)};
  }
  Vec3 apply(const Vec3& x) const { return scale * rotate(x) + translation; }
};

Motion random_motion(std::uint64_t seed) {
  SplitMix64 random(seed ^ kMotionStream);
  // A normalised Gaussian 4-vector is a uniformly distributed unit quaternion.
  std::array<double, 4> q{};
  double length = 0;
  while (length < 1e-6) {
    for (double& c : q) c = random.normal();
    length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  }
  const double w = q[0] / length, x = q[1] / length, y = q[2] / length, z = q[3] / length;
  Motion motion;
  motion.rotation_rows = {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                           {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                           {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
  motion.scale = std::exp(std::log(0.1) + random.uniform() * std::log(100.0));
  for (double& t : motion.translation) t = -5 + 10 * random.uniform();
  return motion;
}

double box_diagonal(const std::vector<Vec3>& positions) {
  Vec3 lo = positions[0], hi = positions[0];
  for (const Vec3& p : positions) {
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  }
  return shape_detail::norm(hi - lo);
}

/// Region primitives in the moved frame, in the canonical form of primitive.hpp.
std::vector<Primitive> canonical_regions(const PatchBuilder& builder, const Motion& motion,
                                         const std::vector<Vec3>& positions) {
  const auto& surfaces = builder.regions();
  std::vector<Vec3> weighted_centroid(surfaces.size(), Vec3{0, 0, 0});
  std::vector<double> area(surfaces.size(), 0.0);
  for (std::size_t t = 0; t < builder.triangles().size(); ++t) {
    const Triangle& tri = builder.triangles()[t];
    const Vec3 &a = positions[tri[0]], &b = positions[tri[1]], &c = positions[tri[2]];
    const double triangle_area = 0.5 * shape_detail::norm(shape_detail::cross(b - a, c - a));
    const std::uint32_t r = builder.triangle_regions()[t];
    weighted_centroid[r] = weighted_centroid[r] + (triangle_area / 3) * (a + b + c);
    area[r] += triangle_area;
  }
  std::vector<Primitive> regions;
  for (std::size_t r = 0; r < surfaces.size(); ++r) {
    const Primitive& local = surfaces[r].primitive;
    const Vec3 centroid = (1.0 / area[r]) * weighted_centroid[r];
    Primitive moved;
    moved.type = local.type;
    switch (local.type) {
      case PrimitiveType::Plane:
        moved.point = centroid;
        moved.axis = normalized(motion.rotate(local.axis));
        break;
      case PrimitiveType::Cylinder: {
        Vec3 axis = normalized(motion.rotate(local.axis));
        const auto largest = std::max_element(
            axis.begin(), axis.end(), [](double u, double v) { return std::abs(u) < std::abs(v); });
        if (*largest < 0) axis = -1.0 * axis;
        const Vec3 on_axis = motion.apply(local.point);
        moved.axis = axis;
        moved.point = on_axis + dot(centroid - on_axis, axis) * axis;
        moved.radius = motion.scale * local.radius;
        break;
      }
      case PrimitiveType::Cone:
        moved.point = motion.apply(local.point);
        moved.axis = normalized(motion.rotate(local.axis));
        moved.half_angle = local.half_angle;
        break;
      case PrimitiveType::Torus: {
        Vec3 axis = normalized(motion.rotate(local.axis));
        const auto largest = std::max_element(
            axis.begin(), axis.end(), [](double u, double v) { return std::abs(u) < std::abs(v); });
        if (*largest < 0) axis = -1.0 * axis;
        moved.point = motion.apply(local.point);
        moved.axis = axis;
        moved.radius = motion.scale * local.radius;
        moved.minor_radius = motion.scale * local.minor_radius;
        break;
      }
      default:  // sphere
        moved.point = motion.apply(local.point);
        moved.radius = motion.scale * local.radius;
        break;
    }
    regions.push_back(moved);
  }
  return regions;
}

/// Moves each vertex along its area-weighted normal by N(0, sigma).
void add_normal_noise(std::vector<Vec3>& positions, const std::vector<Triangle>& triangles,
                      double sigma, std::uint64_t seed) {
  const std::vector<Vec3> normals = shape_detail::area_weighted_normal_sums(positions, triangles);
  SplitMix64 random(seed ^ kNoiseStream);
  for (std::size_t v = 0; v < positions.size(); ++v) {
    const double offset = sigma * random.normal();  // drawn for every vertex: stable stream
    if (shape_detail::norm(normals[v]) > 0) {
      positions[v] = positions[v] + offset * normalized(normals[v]);
    }
  }
}

void check_options(const ShapeOptions& options) {
  if (!(options.edge_length > 0 && options.edge_length <= 1)) {
    throw InvalidInputError("make_shape: edge_length must be in (0, 1], got " +
                            std::to_string(options.edge_length));
  }
  if (options.segments < 3) {
    throw InvalidInputError("make_shape: segments must be at least 3, got " +
                            std::to_string(options.segments));
  }
  if (!(options.noise >= 0 && std::isfinite(options.noise))) {
    throw InvalidInputError("make_shape: noise must be finite and non-negative, got " +
                            std::to_string(options.noise));
  }
}

}  // namespace

std::vector<std::string> shape_names() {
  std::vector<std::string> names;
  for (const auto& entry : shape_detail::catalogue()) names.emplace_back(entry.name);
  return names;
}

GroundTruthShape make_shape(std::string_view name, const ShapeOptions& options) {
  check_options(options);
  const auto& entries = shape_detail::catalogue();
  const auto entry =
      std::find_if(entries.begin(), entries.end(), [&](const auto& e) { return e.name == name; });
  if (entry == entries.end()) {
    throw InvalidInputError("make_shape: unknown shape '" + std::string(name) + "'");
  }
  const PatchBuilder builder = entry->build(options);

  const Motion motion = options.random_motion ? random_motion(options.seed) : Motion{};
  std::vector<Vec3> positions = builder.positions();
  if (options.random_motion) {
    for (Vec3& p : positions) p = motion.apply(p);
  }

  GroundTruthShape shape;
  shape.name = std::string(name);
  shape.regions = canonical_regions(builder, motion, positions);
  shape.region_of_face = builder.triangle_regions();
  if (options.noise > 0) {
    add_normal_noise(positions, builder.triangles(), options.noise * box_diagonal(positions),
                     options.seed);
  }

  Mesh& mesh = shape.mesh;
  mesh.positions = std::move(positions);
  mesh.triangles = builder.triangles();
  const auto face_count = static_cast<std::uint32_t>(mesh.triangles.size());
  mesh.polygon_offsets.assign(1, 0);
  mesh.polygon_vertices.clear();
  mesh.face_of_triangle.resize(face_count);
  for (std::uint32_t f = 0; f < face_count; ++f) {
    mesh.polygon_vertices.insert(mesh.polygon_vertices.end(), mesh.triangles[f].begin(),
                                 mesh.triangles[f].end());
    mesh.polygon_offsets.push_back(3 * (f + 1));
    mesh.face_of_triangle[f] = f;
  }
  return shape;
}

}  // namespace primseg
