#include "primseg/bilateral_smoothing.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

#include "edge_sides.hpp"
#include "eigen_conversions.hpp"
#include "parallel.hpp"
#include "primseg/dual_graph.hpp"
#include "primseg/error.hpp"
#include "vertex_triangles.hpp"

namespace primseg {
namespace {

using detail::to_eigen;
using detail::to_vec3;

// A vertex on more triangles than this (a fan's hub, a book's spine, a cone's apex of many
// segments) brings only the faces across an edge into its triangles' rings: all of them would
// make the rings, their sorting and every pass O(Σ valence²), hours on a 100,000-page book, for
// faces that the spatial Gaussian mostly weighs down anyway. Ordinary meshes (valence about 6)
// are far below it and get exactly the vertex rings.
constexpr std::uint32_t kMaxRingValence = 64;

// The faces sharing a vertex with each face (itself included), as compressed rows, sorted; at a
// vertex above kMaxRingValence, only those sharing an edge with it, linked at a non-manifold edge
// as the dual graph links them (append_cluster_links, each triangle its own cluster).
std::vector<std::vector<std::uint32_t>> face_neighbourhoods(const Mesh& mesh,
                                                            const VertexTriangles& around) {
  const auto crowded = [&](std::uint32_t v) {
    return around.offsets[v + 1] - around.offsets[v] > kMaxRingValence;
  };
  std::vector<std::vector<std::uint32_t>> rings(mesh.triangle_count());
  bool any_crowded = false;
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    std::vector<std::uint32_t>& ring = rings[t];
    ring.push_back(t);
    for (const std::uint32_t v : mesh.triangles[t]) {
      if (crowded(v)) {
        any_crowded = true;
        continue;
      }
      ring.insert(ring.end(), around.triangles.begin() + around.offsets[v],
                  around.triangles.begin() + around.offsets[v + 1]);
    }
  }
  // Across an edge between two crowded vertices, the triangles would meet in no ring otherwise.
  if (any_crowded) {
    std::vector<std::uint32_t> own_cluster(mesh.triangle_count());
    std::iota(own_cluster.begin(), own_cluster.end(), 0u);
    const std::vector<detail::EdgeSide> sides = detail::edge_sides(mesh, own_cluster);
    std::vector<detail::EdgeSide> scratch;
    std::vector<detail::ClusterLink> links;
    for (std::size_t begin = 0; begin < sides.size();) {
      const std::size_t end = detail::edge_end(sides, begin);
      if (crowded(sides[begin].low) && crowded(sides[begin].high))
        detail::append_cluster_links({sides.data() + begin, end - begin}, scratch, links);
      begin = end;
    }
    for (const detail::ClusterLink& link : links) {
      rings[link.first.triangle].push_back(link.second.triangle);
      rings[link.second.triangle].push_back(link.first.triangle);
    }
  }
  for (std::vector<std::uint32_t>& ring : rings) {
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  }
  return rings;
}

// The triangles' centroids, unit normals (zero for a degenerate triangle) and areas, each normal
// on the side the dual graph oriented its triangle to (`flipped`).
struct FaceGeometry {
  std::vector<Eigen::Vector3d> centroids, normals;
  std::vector<double> areas;
};

FaceGeometry face_geometry(const Mesh& mesh, const std::vector<std::uint8_t>& flipped) {
  const std::uint32_t face_count = mesh.triangle_count();
  FaceGeometry geometry{std::vector<Eigen::Vector3d>(face_count),
                        std::vector<Eigen::Vector3d>(face_count), std::vector<double>(face_count)};
  for (std::uint32_t t = 0; t < face_count; ++t) {
    const Triangle& c = mesh.triangles[t];
    const Eigen::Vector3d a = to_eigen(mesh.positions[c[0]]), b = to_eigen(mesh.positions[c[1]]),
                          d = to_eigen(mesh.positions[c[2]]);
    const Eigen::Vector3d cross = flipped[t] ? (d - a).cross(b - a) : (b - a).cross(d - a);
    geometry.centroids[t] = (a + b + d) / 3;
    geometry.areas[t] = cross.norm() / 2;
    geometry.normals[t] =
        geometry.areas[t] > 0 ? Eigen::Vector3d(cross.normalized()) : Eigen::Vector3d::Zero();
  }
  return geometry;
}

// Normals are compared with the triangles consistently oriented, as the dual graph orients them:
// files often list faces with mixed orientations, and a flipped neighbour would not average
// with a face of the same plane, while one across a sharp wedge would look nearly parallel.
std::vector<std::uint8_t> flipped_triangles(const Mesh& mesh, unsigned threads) {
  std::vector<std::uint8_t> flipped(mesh.triangle_count());
  const DualGraph graph(mesh, VertexWeights::Area, threads);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) flipped[t] = graph.flipped(t) ? 1 : 0;
  return flipped;
}

// The mean centroid distance of faces sharing an edge, estimated over the face rings (faces
// sharing only a vertex are a little farther; the spatial sigma's multiple absorbs it); 1 when
// no face has a neighbour.
double mean_ring_distance(const FaceGeometry& geometry,
                          const std::vector<std::vector<std::uint32_t>>& rings) {
  double distance_sum = 0;
  std::uint64_t distance_count = 0;
  for (std::uint32_t t = 0; t < rings.size(); ++t)
    for (const std::uint32_t u : rings[t])
      if (u != t) {
        distance_sum += (geometry.centroids[t] - geometry.centroids[u]).norm();
        ++distance_count;
      }
  return distance_count ? distance_sum / static_cast<double>(distance_count) : 1;
}

// The passes of the normal filter: each face's normal becomes the mean of its ring's, weighted by
// area and by Gaussians of the centroid distance and of the normal difference. Each face of a pass
// reads only the previous pass: any number of threads.
void filter_normals(FaceGeometry& geometry, const std::vector<std::vector<std::uint32_t>>& rings,
                    double spatial, const BilateralSmoothingOptions& options, unsigned threads) {
  const double spatial_factor = spatial > 0 ? 1 / (2 * spatial * spatial) : 0;
  const double normal_factor = 1 / (2 * options.normal_sigma * options.normal_sigma);
  const std::vector<Eigen::Vector3d>& centroids = geometry.centroids;
  const std::vector<double>& areas = geometry.areas;
  std::vector<Eigen::Vector3d>& normals = geometry.normals;
  std::vector<Eigen::Vector3d> filtered(normals.size());
  for (int pass = 0; pass < options.normal_iterations; ++pass) {
    detail::parallel_for(normals.size(), threads, [&](std::size_t t) {
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
}

// The vertex passes: each vertex moves to lower Σ_f (n_f · (x − c_f))² over its faces, one Jacobi
// step at a time with the centroids of the current positions and the filtered `normals`.
void fit_vertices_to_normals(Mesh& mesh, const VertexTriangles& around,
                             const std::vector<Eigen::Vector3d>& normals, int iterations,
                             unsigned threads) {
  std::vector<Eigen::Vector3d> centroids(mesh.triangle_count());
  std::vector<Vec3> next(mesh.positions.size());
  for (int pass = 0; pass < iterations; ++pass) {
    for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
      const Triangle& c = mesh.triangles[t];
      centroids[t] = (to_eigen(mesh.positions[c[0]]) + to_eigen(mesh.positions[c[1]]) +
                      to_eigen(mesh.positions[c[2]])) /
                     3;
    }
    detail::parallel_for(mesh.vertex_count(), threads, [&](std::size_t v) {
      const Eigen::Vector3d x = to_eigen(mesh.positions[v]);
      Eigen::Vector3d move = Eigen::Vector3d::Zero();
      const std::uint32_t begin = around.offsets[v], end = around.offsets[v + 1];
      for (std::uint32_t i = begin; i < end; ++i) {
        const std::uint32_t t = around.triangles[i];
        move += normals[t] * normals[t].dot(centroids[t] - x);
      }
      const Eigen::Vector3d moved = end > begin ? Eigen::Vector3d(x + move / (end - begin)) : x;
      next[v] = to_vec3(moved);
    });
    mesh.positions.swap(next);
  }
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
  if (mesh.triangle_count() == 0) return smoothed;
  const VertexTriangles around = vertex_triangles(mesh);
  const std::vector<std::vector<std::uint32_t>> rings = face_neighbourhoods(mesh, around);
  FaceGeometry geometry = face_geometry(mesh, flipped_triangles(mesh, options.threads));
  const unsigned threads = detail::thread_count(options.threads);
  filter_normals(geometry, rings, options.spatial_sigma * mean_ring_distance(geometry, rings),
                 options, threads);
  fit_vertices_to_normals(smoothed, around, geometry.normals, options.vertex_iterations, threads);
  return smoothed;
}

}  // namespace primseg
