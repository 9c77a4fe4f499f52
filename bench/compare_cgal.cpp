// primseg_compare_cgal: primseg's full hierarchy side by side with the CGAL segmentations a user
// would pick instead, timed in the same process on the same triangle mesh (see bench/README.md).
//
//   primseg_compare_cgal [--repetitions N] [INPUT...]
//
// INPUT is a mesh of Debian's libcgal-demo ("fandisk.off", "bunny00.off"; bench_support.hpp),
// "shape:box_with_hole" (generated, Uniform tessellation, edge length 0.01) or a path to a mesh
// file primseg reads. Default: fandisk.off bunny00.off shape:box_with_hole.
//
// Per input, four measurements, each the median of N (default 5) wall-clock runs; the runs of
// the four are interleaved (primseg, primseg planes only, region growing, VSA, primseg, ...) so
// that load on the machine affects all four alike:
//   1. primseg: build_hierarchy(mesh) with the default options (plane + cylinder + sphere): the
//      whole merge tree, every K at once (destroying the tree included); and the same with
//      planes only, like for like with region growing;
//   2. CGAL region growing on the faces of a CGAL::Surface_mesh, planes only: one segmentation
//      (neighbour query, least-squares plane region, seed sorting by fit quality, detection);
//   3. CGAL Variational Shape Approximation, approximate_triangle_mesh with
//      max_number_of_proxies(20): L21 metric, hierarchical seeding, 5 relaxations and
//      20 iterations (the defaults), face-to-proxy map as output, no re-meshing.
// Converting primseg's mesh into the Surface_mesh happens once, outside the timings.
//
// Output: a Markdown table on stdout, progress on stderr.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing_on_polygon_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_approximation/approximate_triangle_mesh.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bench_support.hpp"
#include "compare_ransac_quality.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using FaceIndex = SurfaceMesh::Face_index;

// Region growing parameters (CGAL 5.5 Region_growing_on_polygon_mesh).
constexpr double kMaxDistanceFraction = 0.01;  ///< max distance: 1% of the bbox diagonal
constexpr double kMaxAngleDegrees = 20.0;      ///< max angle between face and plane normals
constexpr std::size_t kMinRegionSize = 1;      ///< every face ends up in a region
// VSA parameters.
constexpr std::size_t kProxies = 20;

/// The same triangles as primseg's mesh (its triangulation), as a CGAL Surface_mesh.
struct Converted {
  SurfaceMesh mesh;
  std::size_t rejected_faces = 0;  ///< triangles Surface_mesh refused (non-manifold)
  double diagonal = 0;             ///< bounding-box diagonal
};

Converted convert(const primseg::Mesh& input) {
  Converted out;
  std::vector<SurfaceMesh::Vertex_index> vertices;
  vertices.reserve(input.positions.size());
  std::array<double, 3> low{HUGE_VAL, HUGE_VAL, HUGE_VAL}, high{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const auto& p : input.positions) {
    vertices.push_back(out.mesh.add_vertex(Point(p[0], p[1], p[2])));
    for (int i = 0; i < 3; ++i) {
      low[i] = std::min(low[i], p[i]);
      high[i] = std::max(high[i], p[i]);
    }
  }
  for (const auto& t : input.triangles) {
    const FaceIndex f = out.mesh.add_face(vertices[t[0]], vertices[t[1]], vertices[t[2]]);
    if (f == SurfaceMesh::null_face()) ++out.rejected_faces;
  }
  // Vertices no face uses would only be skipped by both algorithms; drop them.
  std::vector<SurfaceMesh::Vertex_index> isolated;
  for (const auto v : out.mesh.vertices())
    if (out.mesh.is_isolated(v)) isolated.push_back(v);
  for (const auto v : isolated) out.mesh.remove_vertex(v);
  out.mesh.collect_garbage();
  out.diagonal =
      std::sqrt((high[0] - low[0]) * (high[0] - low[0]) + (high[1] - low[1]) * (high[1] - low[1]) +
                (high[2] - low[2]) * (high[2] - low[2]));
  return out;
}

/// Wall-clock and process CPU time of one call, milliseconds.
struct Timing {
  double wall_ms = 0, cpu_ms = 0;
};

double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

template <typename Body>
Timing timed(Body&& body) {
  const double cpu0 = process_cpu_ms();
  const auto wall0 = std::chrono::steady_clock::now();
  body();
  const auto wall1 = std::chrono::steady_clock::now();
  const double cpu1 = process_cpu_ms();
  return {std::chrono::duration<double, std::milli>(wall1 - wall0).count(), cpu1 - cpu0};
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// The median wall-clock and the median CPU time of a measurement's runs, each on its own.
Timing median(const std::vector<Timing>& runs) {
  std::vector<double> wall, cpu;
  for (const Timing& run : runs) wall.push_back(run.wall_ms), cpu.push_back(run.cpu_ms);
  return {median(std::move(wall)), median(std::move(cpu))};
}

/// primseg: the whole tree with these types. Returns the number of merges (to keep the work
/// observable).
std::size_t run_primseg(const std::shared_ptr<const primseg::Mesh>& mesh,
                        std::vector<primseg::PrimitiveType> primitives) {
  primseg::HierarchyOptions options;
  options.primitives = std::move(primitives);
  const primseg::Hierarchy tree = primseg::build_hierarchy(mesh, options);
  return tree.merges().size();
}

/// CGAL region growing, planes only. Returns the number of regions.
std::size_t run_region_growing(const SurfaceMesh& mesh, double max_distance) {
  namespace RG = CGAL::Shape_detection::Polygon_mesh;
  using FaceRange = SurfaceMesh::Face_range;
  using NeighborQuery = RG::One_ring_neighbor_query<SurfaceMesh, FaceRange>;
  using RegionType = RG::Least_squares_plane_fit_region<Kernel, SurfaceMesh, FaceRange>;
  using Sorting =
      RG::Least_squares_plane_fit_sorting<Kernel, SurfaceMesh, NeighborQuery, FaceRange>;
  using RegionGrowing = CGAL::Shape_detection::Region_growing<FaceRange, NeighborQuery, RegionType,
                                                              typename Sorting::Seed_map>;

  const FaceRange face_range = faces(mesh);
  NeighborQuery neighbor_query(mesh);
  // The vertex-point map must be passed: its default-constructed value is a null map.
  RegionType region_type(mesh, max_distance, kMaxAngleDegrees, kMinRegionSize, mesh.points());
  Sorting sorting(mesh, neighbor_query, mesh.points());
  sorting.sort();
  RegionGrowing region_growing(face_range, neighbor_query, region_type, sorting.seed_map());
  std::vector<std::vector<std::size_t>> regions;
  region_growing.detect(std::back_inserter(regions));
  return regions.size();
}

/// Output of VSA: the proxy of each face, in a vector indexed by the face index (Surface_mesh
/// face indices are 0..F-1 after collect_garbage()).
struct FaceToProxy {
  using key_type = FaceIndex;
  using value_type = std::size_t;
  using reference = std::size_t&;
  using category = boost::read_write_property_map_tag;
  std::vector<std::size_t>* values;
  friend void put(const FaceToProxy& map, FaceIndex f, std::size_t proxy) {
    (*map.values)[static_cast<std::size_t>(f)] = proxy;
  }
  friend std::size_t get(const FaceToProxy& map, FaceIndex f) {
    return (*map.values)[static_cast<std::size_t>(f)];
  }
};

/// CGAL VSA at kProxies proxies. Returns the proxy of each face.
std::vector<std::size_t> run_vsa(const SurfaceMesh& mesh) {
  std::srand(0);  // VSA draws seeds with std::rand: the same sequence every run
  std::vector<std::size_t> proxy_of_face(mesh.number_of_faces());
  CGAL::Surface_mesh_approximation::approximate_triangle_mesh(
      mesh, CGAL::parameters::max_number_of_proxies(kProxies).face_proxy_map(
                FaceToProxy{&proxy_of_face}));
  return proxy_of_face;
}

std::size_t distinct(const std::vector<std::size_t>& values) {
  return std::set<std::size_t>(values.begin(), values.end()).size();
}

std::shared_ptr<const primseg::Mesh> load_input(const std::string& input) {
  if (input.starts_with("shape:")) {
    primseg::ShapeOptions options;
    options.tessellation = primseg::Tessellation::Uniform;
    options.edge_length = 0.01;
    return std::make_shared<const primseg::Mesh>(
        primseg::make_shape(input.substr(6), options).mesh);
  }
  const std::filesystem::path path = std::filesystem::exists(input)
                                         ? std::filesystem::path(input)
                                         : primseg::bench::cgal_mesh(input);
  return std::make_shared<const primseg::Mesh>(primseg::read_mesh(path));
}

struct Row {
  std::string input;
  std::size_t faces = 0, triangles = 0, rejected = 0;
  Timing primseg, primseg_planes, region_growing, vsa;  // medians
  std::size_t regions = 0, proxies = 0;
};

/// The first three fields of /proc/loadavg ("" if unavailable).
std::string load_average() {
  std::ifstream file("/proc/loadavg");
  std::string one, five, fifteen;
  if (!(file >> one >> five >> fifteen)) return "";
  return one + " " + five + " " + fifteen;
}

std::string fixed(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, value);
  return buffer;
}

std::string grouped(std::size_t value) {
  std::string digits = std::to_string(value), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  int repetitions = 5, seeds = 1;
  bool quality = false;
  std::vector<std::string> inputs;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--repetitions" && i + 1 < argc) {
      repetitions = std::max(1, std::atoi(argv[++i]));
    } else if (arg == "--quality") {
      quality = true;
    } else if (arg == "--seeds" && i + 1 < argc) {
      seeds = std::max(1, std::atoi(argv[++i]));
    } else if (arg == "-h" || arg == "--help") {
      std::cout << "usage: primseg_compare_cgal [--repetitions N] [INPUT...]\n"
                   "       primseg_compare_cgal --quality [--seeds N]\n"
                   "INPUT: fandisk.off | bunny00.off (libcgal-demo) | shape:box_with_hole | "
                   "path\n"
                   "--quality: primseg and CGAL Efficient RANSAC on the generated shapes with "
                   "ground truth (N random poses each, default 1)\n";
      return 0;
    } else {
      inputs.push_back(arg);
    }
  }
  if (quality) {
    try {
      return run_ransac_quality_comparison(seeds);
    } catch (const std::exception& e) {
      std::cerr << "primseg_compare_cgal: " << e.what() << "\n";
      return 1;
    }
  }
  if (inputs.empty()) inputs = {"fandisk.off", "bunny00.off", "shape:box_with_hole"};

  const std::string load_before = load_average();
  std::vector<Row> rows;
  try {
    for (const std::string& input : inputs) {
      Row row;
      row.input = input;
      const auto mesh = load_input(input);
      row.faces = mesh->face_count();
      row.triangles = mesh->triangle_count();
      const Converted converted = convert(*mesh);
      row.rejected = converted.rejected_faces;
      const double max_distance = kMaxDistanceFraction * converted.diagonal;

      std::vector<Timing> primseg_runs, planes_runs, region_growing_runs, vsa_runs;
      for (int r = 0; r < repetitions; ++r) {
        std::cerr << input << ": run " << (r + 1) << "/" << repetitions << "\r" << std::flush;
        primseg_runs.push_back(
            timed([&] { (void)run_primseg(mesh, primseg::HierarchyOptions{}.primitives); }));
        planes_runs.push_back(
            timed([&] { (void)run_primseg(mesh, {primseg::PrimitiveType::Plane}); }));
        region_growing_runs.push_back(
            timed([&] { row.regions = run_region_growing(converted.mesh, max_distance); }));
        std::vector<std::size_t> proxy_of_face;
        vsa_runs.push_back(timed([&] { proxy_of_face = run_vsa(converted.mesh); }));
        row.proxies = distinct(proxy_of_face);
      }
      std::cerr << "\n";
      row.primseg = median(primseg_runs);
      row.primseg_planes = median(planes_runs);
      row.region_growing = median(region_growing_runs);
      row.vsa = median(vsa_runs);
      rows.push_back(row);
    }
  } catch (const std::exception& e) {
    std::cerr << "primseg_compare_cgal: " << e.what() << "\n";
    return 1;
  }

  std::cout << "| input | faces | primseg full tree (ms) | primseg full tree, planes only (ms) "
               "| CGAL region growing (ms) | regions | CGAL VSA "
            << kProxies
            << " proxies (ms) | primseg / region growing | primseg planes only / region growing "
               "| VSA / primseg |\n"
               "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Row& row : rows) {
    std::cout << "| " << row.input << " | " << grouped(row.faces) << " | "
              << fixed(row.primseg.wall_ms, 1) << " | " << fixed(row.primseg_planes.wall_ms, 1)
              << " | " << fixed(row.region_growing.wall_ms, 1) << " | " << row.regions << " | "
              << fixed(row.vsa.wall_ms, 1) << " | "
              << fixed(row.primseg.wall_ms / row.region_growing.wall_ms, 2) << " | "
              << fixed(row.primseg_planes.wall_ms / row.region_growing.wall_ms, 2) << " | "
              << fixed(row.vsa.wall_ms / row.primseg.wall_ms, 1) << " |\n";
  }
  std::cout << "\nWall-clock medians of " << repetitions
            << " interleaved runs in one process. Median process CPU time (ms), "
               "primseg / primseg planes only / region growing / VSA:";
  for (const Row& row : rows)
    std::cout << " " << row.input << " " << fixed(row.primseg.cpu_ms, 1) << " / "
              << fixed(row.primseg_planes.cpu_ms, 1) << " / " << fixed(row.region_growing.cpu_ms, 1)
              << " / " << fixed(row.vsa.cpu_ms, 1) << ";";
  std::cout << " hardware threads: " << std::thread::hardware_concurrency()
            << "; load average before / after: " << load_before << " / " << load_average() << ".\n";
  std::cout << "Region growing: planes, max distance " << kMaxDistanceFraction * 100
            << "% of the bounding-box diagonal, max angle " << kMaxAngleDegrees
            << " degrees, min region size " << kMinRegionSize
            << ", seeds sorted by plane-fit quality. VSA: L21 metric, hierarchical seeding, "
               "max_number_of_proxies("
            << kProxies << "), 5 relaxations, 20 iterations, no re-meshing (";
  for (std::size_t i = 0; i < rows.size(); ++i)
    std::cout << (i ? ", " : "") << rows[i].input << ": " << rows[i].proxies << " proxies used";
  std::cout << ").\n";
  for (const Row& row : rows) {
    if (row.triangles != row.faces)
      std::cout << "Note: " << row.input << " has " << row.faces << " input faces, "
                << row.triangles << " triangles; CGAL runs on the triangles.\n";
    if (row.rejected != 0)
      std::cout << "Note: " << row.input << ": Surface_mesh rejected " << row.rejected
                << " non-manifold triangles.\n";
  }
  return 0;
}
