// primseg_bench_memory: peak resident memory of one full hierarchy build (see bench/README.md).
//
//   primseg_bench_memory MESH_FILE [OPTIONS]
//   primseg_bench_memory --cgal NAME [OPTIONS]            (a libcgal-demo mesh, e.g. fandisk.off)
//   primseg_bench_memory --shape NAME [EDGE_LENGTH] [OPTIONS]  (generated, Uniform tessellation)
//
// OPTIONS: --exact-costs, --eager (CandidateEvaluation::Eager: lazy evaluation's reference, the
// same tree), --threads N (HierarchyOptions::threads, default 0: all),
// --merge-batch-tolerance T (default 0: the exact order), --regions N (default 1: the exact
// order), --read-only (read the input, print read_seconds, build nothing; bench/read_speed.sh)
// --face-order auto|spatial|as-listed (HierarchyOptions::face_order, default auto) and
// --primitives LIST (HierarchyOptions::primitives, comma-separated, default plane,cylinder,sphere).
//
// Prints one line of key=value pairs:
//   faces             input faces F
//   baseline_rss      resident set size before the input is read or generated (bytes)
//   input_rss         resident set size once the mesh is in memory (bytes)
//   peak_rss          getrusage ru_maxrss at the end, after the hierarchy is built (bytes)
//   bytes_per_face    peak_rss / F (the whole process)
//   hierarchy_bytes_per_face  (peak_rss - input_rss) / F: what the build adds to the mesh
//   build_seconds     wall-clock time of the build (HierarchyBuilder and finish(), as
//                     build_hierarchy does), destroying the tree included
//   evaluations       candidate evaluations of the build (HierarchyBuilder::evaluation_count())
//   evaluations_per_face  evaluations / F
//   read_seconds      wall-clock time of read_mesh, in this fresh process (a mesh file only; 0
//                     for a generated shape), page faults of its arrays included as a user meets
//                     them
//   setup_seconds     of build_seconds, the HierarchyBuilder constructor: the dual graph, the
//                     first evaluation of every candidate and the queue
//   merge_seconds     of build_seconds, finish(): the merge loop and the tree's arrays
// One build per process, so that ru_maxrss is this build's peak and nothing else's. The build is
// the function build_and_destroy_tree alone, so that bench/instructions.sh can count its
// instructions (valgrind --toggle-collect) without reading or generating the input.

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include "bench_support.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_io.hpp"

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: primseg_bench_memory MESH_FILE [OPTIONS]\n"
               "       primseg_bench_memory --cgal NAME [OPTIONS]\n"
               "       primseg_bench_memory --shape NAME [EDGE_LENGTH] [OPTIONS]\n"
               "OPTIONS: --exact-costs --eager --threads N --merge-batch-tolerance T --regions N\n"
               "         --read-only --face-order auto|spatial|as-listed --primitives LIST\n");
  return 2;
}

struct BuildFigures {
  std::size_t merges = 0;
  std::uint64_t evaluations = 0;
  /// The builder's constructor (dual graph, first evaluation of every candidate, queue) and
  /// finish() (the merge loop), in seconds.
  double setup_seconds = 0;
  double merge_seconds = 0;
};

// Not inlined: bench/instructions.sh counts the instructions of this function alone.
[[gnu::noinline]] BuildFigures build_and_destroy_tree(std::shared_ptr<const primseg::Mesh> mesh,
                                                      const primseg::HierarchyOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  primseg::HierarchyBuilder builder(std::move(mesh), options);
  const auto built = std::chrono::steady_clock::now();
  const primseg::Hierarchy tree = builder.finish();
  const auto merged = std::chrono::steady_clock::now();
  return {tree.merges().size(), builder.evaluation_count(),
          std::chrono::duration<double>(built - start).count(),
          std::chrono::duration<double>(merged - built).count()};
}

int run(int argc, char** argv) {
  using namespace primseg;
  bench::InputArgument input;
  HierarchyOptions options;
  bool read_only = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--read-only") {
      read_only = true;
    } else if (arg == "--exact-costs") {
      options.exact_costs = true;
    } else if (arg == "--eager") {
      options.evaluation = CandidateEvaluation::Eager;
    } else if (arg == "--threads" && i + 1 < argc) {
      options.threads = bench::count_argument(arg, argv[++i], 0, 1024, "thread");
    } else if (arg == "--merge-batch-tolerance" && i + 1 < argc) {
      options.merge_batch_tolerance = bench::number_argument(arg, argv[++i]);
    } else if (arg == "--primitives" && i + 1 < argc) {
      options.primitives = bench::primitives_argument(arg, argv[++i]);
    } else if (arg == "--regions" && i + 1 < argc) {
      options.regions = bench::count_argument(arg, argv[++i], 1, 256, "region");
    } else if (arg == "--face-order" && i + 1 < argc) {
      const std::string order = argv[++i];
      if (order == "auto")
        options.face_order = FaceOrder::Automatic;
      else if (order == "spatial")
        options.face_order = FaceOrder::Spatial;
      else if (order == "as-listed")
        options.face_order = FaceOrder::AsListed;
      else
        throw std::invalid_argument("--face-order: auto, spatial or as-listed");
    } else if (!input.take(argc, argv, i)) {
      return usage();
    }
  }
  if (input.kind == bench::InputArgument::Kind::None) return usage();

  const std::size_t baseline = bench::current_rss_bytes();
  std::shared_ptr<const Mesh> mesh;
  double read_seconds = 0;
  if (input.kind == bench::InputArgument::Kind::Shape) {
    mesh = std::make_shared<const Mesh>(input.load());
  } else {
    const std::filesystem::path path = input.file();
    const auto read_start = std::chrono::steady_clock::now();
    mesh = std::make_shared<const Mesh>(read_mesh(path));
    read_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
  }
  const std::size_t input_rss = bench::current_rss_bytes();
  if (read_only) {
    std::printf("input=%s faces=%u read_seconds=%.4f\n", input.name.c_str(), mesh->face_count(),
                read_seconds);
    return 0;
  }

  const auto start = std::chrono::steady_clock::now();
  const BuildFigures build = build_and_destroy_tree(mesh, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::size_t peak = bench::peak_rss_bytes();

  const double faces = mesh->face_count();
  std::printf(
      "input=%s faces=%u merges=%zu baseline_rss=%zu input_rss=%zu peak_rss=%zu "
      "bytes_per_face=%.0f hierarchy_bytes_per_face=%.0f build_seconds=%.3f evaluations=%llu "
      "evaluations_per_face=%.3f read_seconds=%.4f setup_seconds=%.3f merge_seconds=%.3f\n",
      input.name.c_str(), mesh->face_count(), build.merges, baseline, input_rss, peak,
      static_cast<double>(peak) / faces,
      static_cast<double>(peak > input_rss ? peak - input_rss : 0) / faces, seconds,
      static_cast<unsigned long long>(build.evaluations),
      static_cast<double>(build.evaluations) / faces, read_seconds, build.setup_seconds,
      build.merge_seconds);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return primseg::bench::main_reporting_errors("primseg_bench_memory", run, argc, argv);
}
