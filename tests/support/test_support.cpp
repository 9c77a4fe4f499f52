#include "support/test_support.hpp"

#include <gtest/gtest.h>

#include <pthread.h>
#include <sys/wait.h>
#include <unistd.h>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <mutex>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "primseg/cut.hpp"
#include "primseg/shape_generator.hpp"

namespace primseg::testing {

std::filesystem::path cgal_mesh(const std::string& name) {
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  const std::filesystem::path archive = "/usr/share/doc/libcgal-dev/data.tar.gz";
  const std::filesystem::path cache = std::filesystem::temp_directory_path() / "primseg-cgal-data";
  const std::filesystem::path path = cache / "data" / "meshes" / name;
  if (std::filesystem::exists(path)) return path;
  if (!std::filesystem::exists(archive)) {
    ADD_FAILURE() << archive << " is missing: install Debian's libcgal-demo";
    return path;
  }
  std::filesystem::create_directories(cache);
  const std::string command =
      "tar xzf " + archive.string() + " -C " + cache.string() + " data/meshes/" + name + " 2>&1";
  if (run_command(command) != 0)
    ADD_FAILURE() << "could not extract " << name << " from " << archive;
  return path;
}

std::filesystem::path temp_directory(const std::string& tag) {
  static std::atomic<int> counter{0};
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("primseg-test-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

namespace {

// Sets the default stack size of new threads; false if the system refuses the value.
bool set_default_stack_size(std::size_t bytes) {
  pthread_attr_t attributes;
  if (::pthread_getattr_default_np(&attributes) != 0) return false;
  const bool set = ::pthread_attr_setstacksize(&attributes, bytes) == 0 &&
                   ::pthread_setattr_default_np(&attributes) == 0;
  ::pthread_attr_destroy(&attributes);
  return set;
}

}  // namespace

RefuseNewThreads::RefuseNewThreads() {
  pthread_attr_t attributes;
  if (::pthread_getattr_default_np(&attributes) == 0) {
    ::pthread_attr_getstacksize(&attributes, &previous_stack_size_);
    ::pthread_attr_destroy(&attributes);
  }
  // 64 TiB: no address space (47 bits) and no memory holds it.
  EXPECT_TRUE(set_default_stack_size(std::size_t{1} << 46));
}

RefuseNewThreads::~RefuseNewThreads() {
  EXPECT_TRUE(set_default_stack_size(previous_stack_size_));
}

std::string file_contents(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

std::filesystem::path cli_path() {
  return PRIMSEG_CLI_PATH;
}

int run_command(const std::string& command, std::string* output) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buffer;
  std::string text;
  std::size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) text.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  if (output) *output = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::array<std::array<double, 3>, 3> random_rotation(std::mt19937_64& rng) {
  // A unit quaternion with uniform random direction: Shoemake's method.
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double u1 = uniform(rng), u2 = 2 * M_PI * uniform(rng), u3 = 2 * M_PI * uniform(rng);
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const double w = a * std::sin(u2), x = a * std::cos(u2), y = b * std::sin(u3),
               z = b * std::cos(u3);
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
           {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
           {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}}};
}

void transform(Mesh& mesh, const std::array<std::array<double, 3>, 3>& rotation, double scale,
               const Vec3& translation) {
  for (Vec3& p : mesh.positions) {
    Vec3 q{};
    for (int r = 0; r < 3; ++r)
      q[r] = scale * (rotation[r][0] * p[0] + rotation[r][1] * p[1] + rotation[r][2] * p[2]) +
             translation[r];
    p = q;
  }
}

}  // namespace primseg::testing

namespace primseg::testing {

Mesh book(std::uint32_t pages) {
  std::vector<Vec3> positions = {{0, 0, 0}, {0, 0, 1}};
  std::vector<Triangle> triangles;
  for (std::uint32_t i = 0; i < pages; ++i) {
    const double angle = 2 * std::numbers::pi * i / pages;
    positions.push_back({std::cos(angle), std::sin(angle), 0.5});
    triangles.push_back({0, 1, i + 2});
  }
  return Mesh::from_triangles(positions, triangles);
}

Mesh concatenated(const std::vector<Mesh>& parts) {
  std::vector<Vec3> positions;
  std::vector<std::uint32_t> offsets{0}, vertices;
  for (const Mesh& part : parts) {
    const auto base = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), part.positions.begin(), part.positions.end());
    for (std::uint32_t f = 0; f < part.face_count(); ++f) {
      for (std::uint32_t v : part.polygon(f)) vertices.push_back(base + v);
      offsets.push_back(static_cast<std::uint32_t>(vertices.size()));
    }
  }
  return Mesh::from_polygons(std::move(positions), std::move(offsets), std::move(vertices));
}

Mesh noisy_uniform_shape(const std::string& name) {
  return noisy_uniform_truth(name, 1, 0.003).mesh;
}

GroundTruthShape moved_shape_truth(const std::string& name, Tessellation tessellation,
                                   std::uint64_t seed, double noise) {
  ShapeOptions options;
  options.tessellation = tessellation;
  options.noise = noise;
  options.random_motion = true;
  options.seed = seed;
  return make_shape(name, options);
}

GroundTruthShape noisy_uniform_truth(const std::string& name, std::uint64_t seed, double noise) {
  return moved_shape_truth(name, Tessellation::Uniform, seed, noise);
}

std::vector<PrimitiveType> every_primitive_type() {
  std::vector<PrimitiveType> types;
  for (int t = 0; t < kPrimitiveTypeCount; ++t) types.push_back(static_cast<PrimitiveType>(t));
  return types;
}

ClusterStats whole_mesh_stats(const DualGraph& graph) {
  return part_stats(graph, std::vector<bool>(graph.face_count(), true));
}

ClusterStats part_stats(const DualGraph& graph, const std::vector<bool>& in_part) {
  std::optional<ClusterStats> stats;
  for (std::uint32_t f = 0; f < graph.face_count(); ++f) {
    if (!in_part[f]) continue;
    if (stats) {
      stats->merge(graph.face_stats(f, true), {});
    } else {
      stats = graph.face_stats(f, true);
    }
  }
  if (!stats) throw std::invalid_argument("part_stats: the part has no face");
  for (const DualEdge& e : graph.edges())
    if (in_part[e.first] && in_part[e.second]) stats->edges += e.shared;
  return stats->centred();
}

double level_rms(const Hierarchy& hierarchy, std::uint32_t k) {
  double error = 0, weight = 0;
  for (std::uint32_t node : cut_by_count(hierarchy, k).nodes) {
    error += hierarchy.error(node);
    weight += hierarchy.weight(node);
  }
  return std::sqrt(error / weight);
}

SegmentationScore score_at_true_count(const GroundTruthShape& shape, const Hierarchy& hierarchy) {
  const Segmentation segmentation =
      cut_by_count(hierarchy, static_cast<std::uint32_t>(shape.regions.size()));
  std::vector<PrimitiveType> types, truth_types;
  for (const ClusterReport& r : describe_clusters(hierarchy, segmentation))
    types.push_back(r.primitive.type);
  for (const Primitive& p : shape.regions) truth_types.push_back(p.type);
  std::vector<double> area(hierarchy.face_count(), 0.0);
  for (std::uint32_t t = 0; t < hierarchy.mesh().triangle_count(); ++t)
    area[hierarchy.mesh().face_of_triangle[t]] += hierarchy.graph().triangle_area(t);
  return score_segmentation(segmentation.labels, shape.region_of_face, area, types, truth_types);
}

}  // namespace primseg::testing
