#include "primseg/bilateral_smoothing.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "eigen_conversions.hpp"
#include "parallel.hpp"
#include "primseg/dual_graph.hpp"
#include "primseg/error.hpp"
#include "vertex_triangles.hpp"

namespace primseg {
namespace {

using detail::to_eigen;
using detail::to_vec3;

// The faces sharing a vertex with each face (itself included), as compressed rows, sorted.
std::vector<std::vector<std::uint32_t>> face_neighbourhoods(const Mesh& mesh,
                                                            const VertexTriangles& around) {
  std::vector<std::vector<std::uint32_t>> rings(mesh.triangle_count());
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    std::vector<std::uint32_t>& ring = rings[t];
    for (const std::uint32_t v : mesh.triangles[t])
      for (std::uint32_t i = around.offsets[v]; i < around.offsets[v + 1]; ++i)
        ring.push_back(around.triangles[i]);
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  }
  return rings;
}

}  // namespace

void validate(const BilateralSmoothingOptions& options) {
  if (options.normal_iterations < 0 || options.vertex_iterations < 0)
    throw InvalidInputError("bilateral smoothing: iteration counts must be non-negative");
  if (!(options.normal_sigma > 0) || !std::isfinite(options.normal_sigma))
    throw InvalidInputError("bilateral smoothing: the normal sigma must be a positive number");
  if (!(options.spatial_sigma > 0) || !std::isfinite(options.spatial_sigma))
    throw InvalidInputError("bilateral smoothing: the spatial sigma must be a positive number");
}

Mesh bilateral_smooth(const Mesh& mesh, const BilateralSmoothingOptions& options) {
  validate(options);
  mesh.validate();
  check_geometric_range(mesh);
  Mesh smoothed = mesh;
  const std::uint32_t face_count = mesh.triangle_count();
  if (face_count == 0) return smoothed;
  const VertexTriangles around = vertex_triangles(mesh);
  const std::vector<std::vector<std::uint32_t>> rings = face_neighbourhoods(mesh, around);

  // Normals are compared with the triangles consistently oriented, as the dual graph orients them:
  // files often list faces with mixed orientations, and a flipped neighbour would not average
  // with a face of the same plane, while one across a sharp wedge would look nearly parallel.
  std::vector<std::uint8_t> flipped(face_count);
  {
    const DualGraph graph(mesh, VertexWeights::Area, options.threads);
    for (std::uint32_t t = 0; t < face_count; ++t) flipped[t] = graph.flipped(t) ? 1 : 0;
  }
  std::vector<Eigen::Vector3d> centroids(face_count), normals(face_count);
  std::vector<double> areas(face_count);
  const auto update_geometry = [&] {
    for (std::uint32_t t = 0; t < face_count; ++t) {
      const Triangle& c = smoothed.triangles[t];
      const Eigen::Vector3d a = to_eigen(smoothed.positions[c[0]]),
                            b = to_eigen(smoothed.positions[c[1]]),
                            d = to_eigen(smoothed.positions[c[2]]);
      const Eigen::Vector3d cross = flipped[t] ? (d - a).cross(b - a) : (b - a).cross(d - a);
      centroids[t] = (a + b + d) / 3;
      areas[t] = cross.norm() / 2;
      normals[t] = areas[t] > 0 ? Eigen::Vector3d(cross.normalized()) : Eigen::Vector3d::Zero();
    }
  };
  update_geometry();

  // The spatial width: the mean centroid distance of faces sharing an edge, estimated over the
  // face rings (faces sharing only a vertex are a little farther; the multiple absorbs it).
  double distance_sum = 0;
  std::uint64_t distance_count = 0;
  for (std::uint32_t t = 0; t < face_count; ++t)
    for (const std::uint32_t u : rings[t])
      if (u != t) {
        distance_sum += (centroids[t] - centroids[u]).norm();
        ++distance_count;
      }
  const double spatial = options.spatial_sigma *
                         (distance_count ? distance_sum / static_cast<double>(distance_count) : 1);
  const double spatial_factor = spatial > 0 ? 1 / (2 * spatial * spatial) : 0;
  const double normal_factor = 1 / (2 * options.normal_sigma * options.normal_sigma);

  // Each face and each vertex of a pass reads only the previous pass: any number of threads.
  const unsigned threads = detail::thread_count(options.threads);
  std::vector<Eigen::Vector3d> filtered(face_count);
  for (int pass = 0; pass < options.normal_iterations; ++pass) {
    detail::parallel_for(face_count, threads, [&](std::size_t t) {
      if (areas[t] == 0) {
        filtered[t] = normals[t];
        return;
      }
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (const std::uint32_t u : rings[t]) {
        const double d2 = (centroids[t] - centroids[u]).squaredNorm();
        const double n2 = (normals[t] - normals[u]).squaredNorm();
        sum += areas[u] * std::exp(-d2 * spatial_factor - n2 * normal_factor) * normals[u];
      }
      const double length = sum.norm();
      filtered[t] = length > 0 ? Eigen::Vector3d(sum / length) : normals[t];
    });
    normals.swap(filtered);
  }

  // Vertex update: each vertex moves to lower Σ_f (n_f · (x − c_f))² over its faces, one Jacobi
  // step at a time with the centroids of the current positions and the filtered normals.
  std::vector<Vec3> next(smoothed.positions.size());
  for (int pass = 0; pass < options.vertex_iterations; ++pass) {
    for (std::uint32_t t = 0; t < face_count; ++t) {
      const Triangle& c = smoothed.triangles[t];
      centroids[t] = (to_eigen(smoothed.positions[c[0]]) + to_eigen(smoothed.positions[c[1]]) +
                      to_eigen(smoothed.positions[c[2]])) /
                     3;
    }
    detail::parallel_for(smoothed.vertex_count(), threads, [&](std::size_t v) {
      const Eigen::Vector3d x = to_eigen(smoothed.positions[v]);
      Eigen::Vector3d move = Eigen::Vector3d::Zero();
      const std::uint32_t begin = around.offsets[v], end = around.offsets[v + 1];
      for (std::uint32_t i = begin; i < end; ++i) {
        const std::uint32_t t = around.triangles[i];
        move += normals[t] * normals[t].dot(centroids[t] - x);
      }
      const Eigen::Vector3d moved = end > begin ? Eigen::Vector3d(x + move / (end - begin)) : x;
      next[v] = to_vec3(moved);
    });
    smoothed.positions.swap(next);
  }
  return smoothed;
}

}  // namespace primseg
