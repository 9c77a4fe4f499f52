#include "denoise_test_support.hpp"

#include <array>
#include <cmath>
#include <vector>

#include "primseg/mesh_distance.hpp"
#include "shape_generator/random.hpp"

namespace primseg::testing {
namespace {

Vec3 normal_of(const Mesh& mesh, const Triangle& t) {
  const Vec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
}

}  // namespace

Mesh with_normal_noise(const Mesh& mesh, double sigma, std::uint64_t seed) {
  std::vector<Vec3> normals(mesh.positions.size(), Vec3{0, 0, 0});
  for (const Triangle& t : mesh.triangles) {
    const Vec3 n = normal_of(mesh, t);  // length: twice the area
    for (const std::uint32_t v : t)
      for (int d = 0; d < 3; ++d) normals[v][d] += n[d];
  }
  Mesh noisy = mesh;
  shape_detail::SplitMix64 random(seed);
  for (std::size_t v = 0; v < normals.size(); ++v) {
    const double length = std::sqrt(normals[v][0] * normals[v][0] + normals[v][1] * normals[v][1] +
                                    normals[v][2] * normals[v][2]);
    const double offset = sigma * random.normal();
    if (length == 0) continue;
    for (int d = 0; d < 3; ++d) noisy.positions[v][d] += offset * normals[v][d] / length;
  }
  return noisy;
}

std::uint32_t inverted_triangles(const Mesh& reference, const Mesh& after) {
  std::uint32_t count = 0;
  for (const Triangle& t : reference.triangles) {
    const Vec3 a = normal_of(reference, t), b = normal_of(after, t);
    if (a[0] * b[0] + a[1] * b[1] + a[2] * b[2] < 0) ++count;
  }
  return count;
}

double vertex_rms_to_surface(const Mesh& mesh, const Mesh& surface) {
  const TriangleBvh bvh(surface);
  double sum = 0;
  for (const Vec3& p : mesh.positions) sum += bvh.closest_point(p).squared_distance;
  return std::sqrt(sum / static_cast<double>(mesh.vertex_count()));
}

double least_squares_floor(const Hierarchy& hierarchy, const Segmentation& level, double sigma) {
  // By PrimitiveType: plane, cylinder, sphere, cone, torus.
  constexpr std::array<int, kPrimitiveTypeCount> kDegreesOfFreedom{3, 5, 4, 6, 7};
  int degrees_of_freedom = 0;
  for (const std::uint32_t node : level.nodes)
    degrees_of_freedom +=
        kDegreesOfFreedom[static_cast<std::size_t>(hierarchy.primitive(node).type)];
  return sigma *
         std::sqrt(degrees_of_freedom / static_cast<double>(hierarchy.mesh().vertex_count()));
}

}  // namespace primseg::testing
