// primseg_bench_memory: peak resident memory of one full hierarchy build (see bench/README.md).
//
//   primseg_bench_memory MESH_FILE [--exact-costs]
//   primseg_bench_memory --cgal NAME [--exact-costs]     (a libcgal-demo mesh, e.g. fandisk.off)
//   primseg_bench_memory --shape NAME [EDGE_LENGTH]      (generated, Uniform tessellation)
//
// Prints one line of key=value pairs:
//   faces             input faces F
//   baseline_rss      resident set size before the input is read or generated (bytes)
//   input_rss         resident set size once the mesh is in memory (bytes)
//   peak_rss          getrusage ru_maxrss at the end, after the hierarchy is built (bytes)
//   bytes_per_face    peak_rss / F (the whole process)
//   hierarchy_bytes_per_face  (peak_rss - input_rss) / F: what the build adds to the mesh
//   build_seconds     wall-clock time of build_hierarchy
// One build per process, so that ru_maxrss is this build's peak and nothing else's.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>

#include "bench_support.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: primseg_bench_memory MESH_FILE [--exact-costs]\n"
               "       primseg_bench_memory --cgal NAME [--exact-costs]\n"
               "       primseg_bench_memory --shape NAME [EDGE_LENGTH] [--exact-costs]\n");
  return 2;
}

int run(int argc, char** argv) {
  using namespace primseg;
  std::string source, name;
  double edge_length = 0.01;
  bool exact_costs = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--exact-costs") {
      exact_costs = true;
    } else if ((arg == "--cgal" || arg == "--shape") && i + 1 < argc && source.empty()) {
      source = arg;
      name = argv[++i];
      if (arg == "--shape" && i + 1 < argc && argv[i + 1][0] != '-')
        edge_length = std::stod(argv[++i]);
    } else if (!arg.starts_with("-") && source.empty()) {
      source = "file";
      name = arg;
    } else {
      return usage();
    }
  }
  if (source.empty()) return usage();

  const std::size_t baseline = bench::current_rss_bytes();
  std::shared_ptr<const Mesh> mesh;
  if (source == "--shape") {
    ShapeOptions options;
    options.tessellation = Tessellation::Uniform;
    options.edge_length = edge_length;
    mesh = std::make_shared<const Mesh>(make_shape(name, options).mesh);
  } else {
    mesh = std::make_shared<const Mesh>(
        read_mesh(source == "--cgal" ? bench::cgal_mesh(name) : std::filesystem::path(name)));
  }
  const std::size_t input = bench::current_rss_bytes();

  HierarchyOptions options;
  options.exact_costs = exact_costs;
  const auto start = std::chrono::steady_clock::now();
  std::size_t merges = 0;
  {
    const Hierarchy tree = build_hierarchy(mesh, options);
    merges = tree.merges().size();
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::size_t peak = bench::peak_rss_bytes();

  const double faces = mesh->face_count();
  std::printf(
      "input=%s faces=%u merges=%zu baseline_rss=%zu input_rss=%zu peak_rss=%zu "
      "bytes_per_face=%.0f hierarchy_bytes_per_face=%.0f build_seconds=%.3f\n",
      name.c_str(), mesh->face_count(), merges, baseline, input, peak,
      static_cast<double>(peak) / faces,
      static_cast<double>(peak > input ? peak - input : 0) / faces, seconds);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "primseg_bench_memory: %s\n", e.what());
    return 1;
  }
}
