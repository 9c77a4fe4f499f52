// primseg_subdivide: large test meshes for the scaling figures (bench/scaling.sh).
//
//   primseg_subdivide IN OUT [--midpoint N] [--trisect] [--noise FRACTION] [--seed S]
//
// --midpoint N splits every triangle into 4 by its edge midpoints, N times (faces × 4^N);
// --trisect then splits every edge in three and every triangle into 9 (faces × 9): bunny00's
// 75,408 faces become 1,206,528 with --midpoint 2 and 10,858,752 with --midpoint 2 --trisect.
// --noise moves every vertex along its area-weighted normal by a Gaussian of standard deviation
// FRACTION × the bounding-box diagonal. The output's format follows its extension (binary PLY
// is the fastest to read).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <unordered_map>

#include "bench_support.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"

namespace {

using primseg::Mesh;
using primseg::Triangle;
using primseg::Vec3;

// Splits every edge into `parts` equal pieces (each edge's points created once, shared by its
// two triangles) and every triangle into parts² triangles with the same orientation.
Mesh split_edges(const Mesh& mesh, std::uint32_t parts) {
  std::vector<Vec3> positions = mesh.positions;
  std::unordered_map<std::uint64_t, std::uint32_t> first_point_of_edge;
  first_point_of_edge.reserve(mesh.triangles.size() * 2);
  auto lerp = [&](std::uint32_t a, std::uint32_t b, double t) {
    const Vec3& p = mesh.positions[a];
    const Vec3& q = mesh.positions[b];
    return Vec3{p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]), p[2] + t * (q[2] - p[2])};
  };
  // Point i (0..parts) along the directed edge a -> b.
  auto edge_point = [&](std::uint32_t a, std::uint32_t b, std::uint32_t i) {
    if (i == 0) return a;
    if (i == parts) return b;
    const std::uint32_t lo = std::min(a, b), hi = std::max(a, b);
    const std::uint64_t key = (std::uint64_t{lo} << 32) | hi;
    auto [it, inserted] =
        first_point_of_edge.try_emplace(key, static_cast<std::uint32_t>(positions.size()));
    if (inserted)
      for (std::uint32_t k = 1; k < parts; ++k)
        positions.push_back(lerp(lo, hi, double(k) / parts));
    return it->second + (a == lo ? i - 1 : parts - 1 - i);
  };
  std::vector<Triangle> triangles;
  triangles.reserve(mesh.triangles.size() * parts * parts);
  std::vector<std::uint32_t> grid;  // row r (0..parts) has parts - r + 1 points
  for (const Triangle& t : mesh.triangles) {
    // Barycentric grid: point (r, c) = t0 + r/parts (t2 − t0) + c/parts (t1 − t0), r + c <= parts.
    grid.clear();
    std::vector<std::uint32_t> row_start;
    for (std::uint32_t r = 0; r <= parts; ++r) {
      row_start.push_back(static_cast<std::uint32_t>(grid.size()));
      for (std::uint32_t c = 0; c + r <= parts; ++c) {
        std::uint32_t id;
        if (r == 0)
          id = edge_point(t[0], t[1], c);
        else if (c == 0)
          id = edge_point(t[0], t[2], r);
        else if (r + c == parts)
          id = edge_point(t[1], t[2], r);
        else {
          const Vec3& p0 = mesh.positions[t[0]];
          const Vec3& p1 = mesh.positions[t[1]];
          const Vec3& p2 = mesh.positions[t[2]];
          const double u = double(c) / parts, v = double(r) / parts;
          Vec3 p;
          for (int k = 0; k < 3; ++k) p[k] = p0[k] + u * (p1[k] - p0[k]) + v * (p2[k] - p0[k]);
          id = static_cast<std::uint32_t>(positions.size());
          positions.push_back(p);
        }
        grid.push_back(id);
      }
    }
    auto at = [&](std::uint32_t r, std::uint32_t c) { return grid[row_start[r] + c]; };
    for (std::uint32_t r = 0; r < parts; ++r)
      for (std::uint32_t c = 0; c + r < parts; ++c) {
        triangles.push_back({at(r, c), at(r, c + 1), at(r + 1, c)});
        if (c + r + 1 < parts) triangles.push_back({at(r, c + 1), at(r + 1, c + 1), at(r + 1, c)});
      }
  }
  return Mesh::from_triangles(std::move(positions), std::move(triangles));
}

void add_normal_noise(Mesh& mesh, double fraction, std::uint64_t seed) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const Vec3& p : mesh.positions) {
    const Eigen::Vector3d x(p[0], p[1], p[2]);
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double sigma = fraction * (hi - lo).norm();
  std::vector<Eigen::Vector3d> normal(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (const Triangle& t : mesh.triangles) {
    auto x = [&](int c) {
      const Vec3& p = mesh.positions[t[c]];
      return Eigen::Vector3d(p[0], p[1], p[2]);
    };
    const Eigen::Vector3d area_normal = (x(1) - x(0)).cross(x(2) - x(0));
    for (int c = 0; c < 3; ++c) normal[t[c]] += area_normal;
  }
  std::mt19937_64 random(seed);
  std::normal_distribution<double> gaussian(0.0, sigma);
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const double length = normal[v].norm();
    const double offset = gaussian(random);
    if (!(length > 0)) continue;
    for (int k = 0; k < 3; ++k) mesh.positions[v][k] += offset * normal[v][k] / length;
  }
}

int run(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: %s IN OUT [--midpoint N] [--trisect] [--noise FRACTION] [--seed S]\n",
                 argv[0]);
    return 1;
  }
  int midpoint = 0;
  bool trisect = false;
  double noise = 0;
  std::uint64_t seed = 1;
  for (int i = 3; i < argc; ++i) {
    const std::string flag = argv[i];
    auto value = [&] {
      if (i + 1 >= argc) throw primseg::InvalidInputError(flag + " needs a value");
      return std::string(argv[++i]);
    };
    if (flag == "--midpoint")
      midpoint = std::stoi(value());
    else if (flag == "--trisect")
      trisect = true;
    else if (flag == "--noise")
      noise = std::stod(value());
    else if (flag == "--seed")
      seed = std::stoull(value());
    else
      throw primseg::InvalidInputError("unknown option " + flag);
  }
  Mesh mesh = primseg::read_mesh(argv[1]);
  for (int level = 0; level < midpoint; ++level) mesh = split_edges(mesh, 2);
  if (trisect) mesh = split_edges(mesh, 3);
  if (noise > 0) add_normal_noise(mesh, noise, seed);
  primseg::write_mesh(argv[2], mesh);
  std::printf("%s: %u vertices, %u faces\n", argv[2], mesh.vertex_count(), mesh.face_count());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return primseg::bench::main_reporting_errors("primseg_subdivide", run, argc, argv);
}
