#include "support/test_support.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <mutex>

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

ClusterStats whole_mesh_stats(const DualGraph& graph) {
  ClusterStats stats = graph.face_stats(0);
  for (std::uint32_t f = 1; f < graph.face_count(); ++f) stats.merge(graph.face_stats(f), {});
  for (const DualEdge& e : graph.edges()) stats.edges += e.shared;
  return stats.centred();
}

}  // namespace primseg::testing

namespace primseg::testing {
namespace {

// Minimum-cost assignment of rows to columns (rows <= columns), O(n² m): the classic
// potentials formulation of the Hungarian method. Returns the column of each row.
std::vector<int> hungarian(const std::vector<std::vector<double>>& cost) {
  const int n = static_cast<int>(cost.size()), m = static_cast<int>(cost[0].size());
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0), v(m + 1, 0), way_cost(m + 1);
  std::vector<int> match(m + 1, 0), way(m + 1, 0);
  for (int row = 1; row <= n; ++row) {
    match[0] = row;
    int column = 0;
    std::fill(way_cost.begin(), way_cost.end(), inf);
    std::vector<char> used(m + 1, 0);
    do {
      used[column] = 1;
      const int r = match[column];
      double delta = inf;
      int next = 0;
      for (int c = 1; c <= m; ++c) {
        if (used[c]) continue;
        const double reduced = cost[r - 1][c - 1] - u[r] - v[c];
        if (reduced < way_cost[c]) {
          way_cost[c] = reduced;
          way[c] = column;
        }
        if (way_cost[c] < delta) {
          delta = way_cost[c];
          next = c;
        }
      }
      for (int c = 0; c <= m; ++c) {
        if (used[c]) {
          u[match[c]] += delta;
          v[c] -= delta;
        } else {
          way_cost[c] -= delta;
        }
      }
      column = next;
    } while (match[column] != 0);
    do {
      const int previous = way[column];
      match[column] = match[previous];
      column = previous;
    } while (column);
  }
  std::vector<int> column_of_row(n, -1);
  for (int c = 1; c <= m; ++c)
    if (match[c]) column_of_row[match[c] - 1] = c - 1;
  return column_of_row;
}

}  // namespace

SegmentationScore score_segmentation(const std::vector<std::uint32_t>& labels,
                                     const std::vector<std::uint32_t>& truth,
                                     const std::vector<double>& area,
                                     const std::vector<PrimitiveType>& types,
                                     const std::vector<PrimitiveType>& truth_types) {
  const std::size_t regions = truth_types.size(), clusters = types.size();
  std::vector<std::vector<double>> overlap(regions, std::vector<double>(clusters, 0.0));
  std::vector<double> region_area(regions, 0.0), cluster_area(clusters, 0.0);
  for (std::size_t f = 0; f < labels.size(); ++f) {
    overlap[truth[f]][labels[f]] += area[f];
    region_area[truth[f]] += area[f];
    cluster_area[labels[f]] += area[f];
  }
  auto iou = [&](std::size_t r, std::size_t c) {
    return overlap[r][c] / (region_area[r] + cluster_area[c] - overlap[r][c]);
  };
  // Pad with empty clusters so every region gets a column.
  const std::size_t columns = std::max(regions, clusters);
  std::vector<std::vector<double>> cost(regions, std::vector<double>(columns, 0.0));
  for (std::size_t r = 0; r < regions; ++r)
    for (std::size_t c = 0; c < clusters; ++c) cost[r][c] = -overlap[r][c];
  const std::vector<int> match = hungarian(cost);
  SegmentationScore score;
  score.min_iou = 1;
  double total_area = 0, typed_area = 0;
  for (std::size_t r = 0; r < regions; ++r) {
    const int c = match[r];
    const double value = c >= 0 && std::size_t(c) < clusters ? iou(r, std::size_t(c)) : 0.0;
    score.mean_iou += value / double(regions);
    score.min_iou = std::min(score.min_iou, value);
    total_area += region_area[r];
    if (c >= 0 && std::size_t(c) < clusters && types[std::size_t(c)] == truth_types[r])
      typed_area += region_area[r];
  }
  score.type_accuracy = total_area > 0 ? typed_area / total_area : 0;
  return score;
}

}  // namespace primseg::testing
