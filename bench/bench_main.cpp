// primseg_bench: timings of the hierarchy, the mesh readers and a cut (see bench/README.md).
//
// Every benchmark measures wall-clock time (UseRealTime) over 5 repetitions and reports the
// mean, median, standard deviation and coefficient of variation of the repetitions. Inputs (mesh
// files, parsed meshes, generated shapes, the hierarchy a cut is taken from) are prepared outside
// the timed loop and cached for the whole run.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "bench_support.hpp"
#include "primseg/cut.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"

namespace primseg::bench {
namespace {

constexpr int kRepetitions = 5;

/// The generated input: box_with_hole, Uniform tessellation, edge length 1% of the diagonal.
constexpr const char* kShapeName = "box_with_hole";
constexpr double kShapeEdgeLength = 0.01;

/// A benchmark input: a CGAL sample mesh file name or "shape:<name>" for a generated shape.
std::shared_ptr<const Mesh> load_input(const std::string& input) {
  static std::map<std::string, std::shared_ptr<const Mesh>> cache;
  auto& mesh = cache[input];
  if (!mesh) {
    if (input.starts_with("shape:")) {
      ShapeOptions options;
      options.tessellation = Tessellation::Uniform;
      options.edge_length = kShapeEdgeLength;
      mesh = std::make_shared<const Mesh>(make_shape(input.substr(6), options).mesh);
    } else {
      mesh = std::make_shared<const Mesh>(read_mesh(cgal_mesh(input)));
    }
  }
  return mesh;
}

/// Runs `body` and turns any exception into a skipped benchmark with the error message.
template <typename Body>
void guarded(benchmark::State& state, Body&& body) {
  try {
    body();
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

void set_face_counters(benchmark::State& state, std::uint32_t faces) {
  state.counters["faces"] = benchmark::Counter(static_cast<double>(faces));
  state.counters["faces_per_second"] =
      benchmark::Counter(static_cast<double>(faces), benchmark::Counter::kIsIterationInvariantRate);
}

/// The full hierarchy (build_hierarchy on a shared mesh: no copy). The Hierarchy's destruction
/// is part of the timed iteration.
void hierarchy(benchmark::State& state, const std::string& input, bool exact_costs) {
  guarded(state, [&] {
    const auto mesh = load_input(input);
    HierarchyOptions options;
    options.exact_costs = exact_costs;
    for (auto _ : state) {
      Hierarchy tree = build_hierarchy(mesh, options);
      benchmark::DoNotOptimize(tree.merges().data());
      benchmark::ClobberMemory();
    }
    set_face_counters(state, mesh->face_count());
  });
}

/// read_mesh of a file (page cache warm after the first iteration); bytes/s is file size / time.
void read(benchmark::State& state, const std::string& name) {
  guarded(state, [&] {
    const auto path = cgal_mesh(name);
    const auto bytes = static_cast<std::int64_t>(std::filesystem::file_size(path));
    std::uint32_t faces = 0;
    for (auto _ : state) {
      const Mesh mesh = read_mesh(path);
      faces = mesh.face_count();
      benchmark::DoNotOptimize(mesh.triangles.data());
    }
    state.SetBytesProcessed(state.iterations() * bytes);
    set_face_counters(state, faces);
  });
}

/// One level of a prebuilt hierarchy: cut_by_count at K clusters, then describe_clusters.
void cut_and_describe(benchmark::State& state, const std::string& input, std::uint32_t clusters) {
  guarded(state, [&] {
    static std::map<std::string, std::unique_ptr<const Hierarchy>> trees;
    auto& tree = trees[input];
    if (!tree) tree = std::make_unique<const Hierarchy>(build_hierarchy(load_input(input)));
    for (auto _ : state) {
      const Segmentation level = cut_by_count(*tree, clusters);
      const auto reports = describe_clusters(*tree, level);
      benchmark::DoNotOptimize(reports.data());
    }
    set_face_counters(state, tree->face_count());
  });
}

benchmark::internal::Benchmark* configure(benchmark::internal::Benchmark* b) {
  return b->UseRealTime()
      ->Repetitions(kRepetitions)
      ->ReportAggregatesOnly(true)
      ->Unit(benchmark::kMillisecond);
}

void register_benchmarks() {
  const std::string shape = std::string("shape:") + kShapeName;
  // A hierarchy build takes long enough that one iteration per repetition is a stable figure:
  // the 5 repetitions are then 5 independent builds and the median is their median.
  configure(benchmark::RegisterBenchmark("hierarchy/fandisk", hierarchy, "fandisk.off", false))
      ->Iterations(1);
  configure(benchmark::RegisterBenchmark("hierarchy/bunny00", hierarchy, "bunny00.off", false))
      ->Iterations(1);
  configure(
      benchmark::RegisterBenchmark("hierarchy/box_with_hole_uniform_0.01", hierarchy, shape, false))
      ->Iterations(1);
  configure(
      benchmark::RegisterBenchmark("hierarchy_exact_costs/fandisk", hierarchy, "fandisk.off", true))
      ->Iterations(1);
  configure(benchmark::RegisterBenchmark("read_mesh/fandisk", read, "fandisk.off"));
  configure(benchmark::RegisterBenchmark("read_mesh/bunny00", read, "bunny00.off"));
  configure(benchmark::RegisterBenchmark("cut_describe_k30/fandisk", cut_and_describe,
                                         "fandisk.off", std::uint32_t{30}));
}

}  // namespace
}  // namespace primseg::bench

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  primseg::bench::register_benchmarks();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
