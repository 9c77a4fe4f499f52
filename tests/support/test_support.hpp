#pragma once
// Shared helpers of the test suite.

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "primseg/mesh.hpp"
#include "primseg/primitive.hpp"
#include "primseg/shape_generator.hpp"

namespace primseg::testing {

/// Euclidean distance between two points.
inline double distance(const Vec3& a, const Vec3& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

/// Path of a mesh shipped by Debian's libcgal-demo (for example "fandisk.off"), extracted from
/// /usr/share/doc/libcgal-dev/data.tar.gz into a cache directory at first use. Fails the
/// calling test (not skips) when the package is missing: CI installs it.
std::filesystem::path cgal_mesh(const std::string& name);

/// A fresh empty directory under the system temp dir, unique per call.
std::filesystem::path temp_directory(const std::string& tag);

/// Path of the primseg executable built with the tests.
std::filesystem::path cli_path();

/// The whole contents of a file, bytes as they are (empty if it cannot be read).
std::string file_contents(const std::filesystem::path& path);

/// Runs a shell command, returns its exit status; stdout+stderr go to *output if given.
int run_command(const std::string& command, std::string* output = nullptr);

/// True when a and b are the same double, bit for bit (so 0 and −0 differ, and a NaN equals
/// itself).
inline bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

/// While alive, the system refuses to start threads, as a process or memory limit would: their
/// default stack is made larger than the address space (pthread_setattr_default_np). Restores
/// the previous default when destroyed.
class RefuseNewThreads {
 public:
  RefuseNewThreads();
  ~RefuseNewThreads();
  RefuseNewThreads(const RefuseNewThreads&) = delete;
  RefuseNewThreads& operator=(const RefuseNewThreads&) = delete;

 private:
  std::size_t previous_stack_size_ = 0;
};

/// A uniformly random rotation (deterministic for a given engine state).
std::array<std::array<double, 3>, 3> random_rotation(std::mt19937_64& rng);

/// Applies x -> scale * R x + t to every vertex.
void transform(Mesh& mesh, const std::array<std::array<double, 3>, 3>& rotation, double scale,
               const Vec3& translation);

}  // namespace primseg::testing

#include "primseg/cluster_stats.hpp"
#include "primseg/dual_graph.hpp"
#include "primseg/evaluation.hpp"
#include "primseg/hierarchy.hpp"

namespace primseg::testing {

/// A grid of (rows + 1) × (cols + 1) vertices p(u, v), u, v in [0, 1], split into 2·rows·cols
/// triangles (diagonals alternating when `alternate`), outward orientation given by p's
/// parametrisation (∂p/∂u × ∂p/∂v).
template <typename Surface>
Mesh grid_mesh(int rows, int cols, Surface&& p, bool alternate = false) {
  std::vector<Vec3> positions;
  for (int i = 0; i <= rows; ++i)
    for (int j = 0; j <= cols; ++j) positions.push_back(p(double(i) / rows, double(j) / cols));
  std::vector<Triangle> triangles;
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>(i * (cols + 1) + j); };
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) {
      if (alternate && (i + j) % 2) {
        triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        triangles.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        triangles.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  return Mesh::from_triangles(std::move(positions), std::move(triangles));
}

/// Every primitive type, in tie order (plane, cylinder, sphere, cone, torus): the
/// `--primitives` list that enables cones and tori.
std::vector<PrimitiveType> every_primitive_type();

/// Several meshes as the components of one (each part's vertices after the previous parts').
Mesh concatenated(const std::vector<Mesh>& parts);

/// A non-manifold "book": `pages` triangles on one spine edge from vertex 0 at (0, 0, 0) to
/// vertex 1 at (0, 0, 1); page i is triangle (0, 1, i + 2), its third vertex on the unit circle
/// at angle 2πi / pages and height 0.5.
Mesh book(std::uint32_t pages);

/// A generated shape (shape_generator.hpp) in its Uniform tessellation with random vertex motion
/// and Gaussian noise of 0.3% of its size along the normals: a small scan-like input.
Mesh noisy_uniform_shape(const std::string& name);
/// A generated shape and its ground truth in `tessellation`, moved by the random rigid motion of
/// `seed`, with Gaussian noise of `noise` times its size along the normals (`primseg eval`'s
/// variants: Cad and Uniform without noise, Uniform with noise 0.002).
GroundTruthShape moved_shape_truth(const std::string& name, Tessellation tessellation,
                                   std::uint64_t seed, double noise);
/// moved_shape_truth() in the Uniform tessellation.
GroundTruthShape noisy_uniform_truth(const std::string& name, std::uint64_t seed, double noise);

/// The tetrahedron with corners (0, 0, 0), (0, 1, 0), (1, 1, 0) and (0, 0, 1) (its `corners`),
/// its four faces listed in that order of corners, two of them facing inwards: files often mix
/// orientations.
struct TetrahedronWithInwardFaces {
  std::vector<Vec3> corners{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}};
  Mesh mesh = Mesh::from_triangles(corners, {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}});
};

/// Statistics of the whole mesh as one cluster, accumulated face by face and edge by edge the way
/// the engine does (corner samples included), with moments centred at the centroid.
ClusterStats whole_mesh_stats(const DualGraph& graph);
/// The same for the faces f with in_part[f] (at least one), with the edges between two of them.
ClusterStats part_stats(const DualGraph& graph, const std::vector<bool>& in_part);

}  // namespace primseg::testing

namespace primseg::testing {

// The scores moved into the library (evaluation.hpp); tests keep their short names.
using primseg::score_segmentation;
using primseg::SegmentationScore;

/// The score of the hierarchy's level with as many clusters as the shape has regions, each
/// cluster typed by its reported (geometric) fit, faces weighted by their area.
SegmentationScore score_at_true_count(const GroundTruthShape& shape, const Hierarchy& hierarchy);

/// sqrt(Σ error / Σ weight) over the clusters of the hierarchy's level with k clusters (working
/// units): how well a level fits, to compare two trees of one mesh.
double level_rms(const Hierarchy& hierarchy, std::uint32_t k);

}  // namespace primseg::testing
