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
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_support.hpp"
#include "model_selection.hpp"
#include "primseg/cut.hpp"
#include "primseg/dual_graph.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/refine.hpp"
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
void hierarchy(benchmark::State& state, const std::string& input, const HierarchyOptions& options) {
  guarded(state, [&] {
    const auto mesh = load_input(input);
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

/// The hierarchy of an input, built once per process (the benchmarks of a level time the level).
const Hierarchy& prebuilt_hierarchy(const std::string& input) {
  static std::map<std::string, std::unique_ptr<const Hierarchy>> trees;
  auto& tree = trees[input];
  if (!tree) tree = std::make_unique<const Hierarchy>(build_hierarchy(load_input(input)));
  return *tree;
}

/// One level of a prebuilt hierarchy: cut_by_count at K clusters, then describe_clusters.
void cut_and_describe(benchmark::State& state, const std::string& input, std::uint32_t clusters) {
  guarded(state, [&] {
    const Hierarchy& tree = prebuilt_hierarchy(input);
    for (auto _ : state) {
      const Segmentation level = cut_by_count(tree, clusters);
      const auto reports = describe_clusters(tree, level);
      benchmark::DoNotOptimize(reports.data());
    }
    set_face_counters(state, tree.face_count());
  });
}

/// Boundary refinement of one level of a prebuilt hierarchy (refine_boundaries with its default
/// 5 passes, each refitting the clusters geometrically), the level cut and described beforehand.
void refine_level(benchmark::State& state, const std::string& input, std::uint32_t clusters) {
  guarded(state, [&] {
    const Hierarchy& tree = prebuilt_hierarchy(input);
    const Segmentation level = cut_by_count(tree, clusters);
    for (auto _ : state) {
      const RefinedLevel refined = refine_boundaries(tree, level);
      benchmark::DoNotOptimize(refined.reports.data());
    }
    set_face_counters(state, tree.face_count());
  });
}

/// One candidate evaluation (what each candidate merge costs, less the queue): the view of the
/// union of two adjacent clusters and model selection over plane, cylinder and sphere.
/// The clusters have `faces` faces each, grown breadth-first on a finely tessellated sphere: the
/// time must not depend on `faces` (the constant-time claim).
void candidate_evaluation(benchmark::State& state, std::uint32_t faces) {
  guarded(state, [&] {
    static std::shared_ptr<const Mesh> mesh;
    static std::unique_ptr<DualGraph> graph;
    if (!graph) {
      ShapeOptions options;
      options.tessellation = Tessellation::Uniform;
      options.edge_length = 0.0025;  // about 300k faces: room for two clusters of 100k
      mesh = std::make_shared<const Mesh>(make_shape("sphere", options).mesh);
      graph = std::make_unique<DualGraph>(*mesh, VertexWeights::Area);
    }
    if (2 * faces > graph->face_count()) throw std::runtime_error("mesh too small");
    // Breadth-first order from face 0: the first `faces` faces are A, the next `faces` are B.
    std::vector<std::vector<std::uint32_t>> neighbours(graph->face_count());
    for (std::uint32_t e = 0; e < graph->edges().size(); ++e) {
      neighbours[graph->edges()[e].first].push_back(e);
      neighbours[graph->edges()[e].second].push_back(e);
    }
    std::vector<int> cluster(graph->face_count(), -1);
    std::vector<std::uint32_t> queue{0};
    std::vector<char> seen(graph->face_count(), 0);
    seen[0] = 1;
    for (std::size_t head = 0; head < queue.size() && head < 2 * std::size_t{faces}; ++head) {
      cluster[queue[head]] = head < faces ? 0 : 1;
      for (std::uint32_t e : neighbours[queue[head]]) {
        const DualEdge& edge = graph->edges()[e];
        const std::uint32_t other = edge.first == queue[head] ? edge.second : edge.first;
        if (!seen[other]) {
          seen[other] = 1;
          queue.push_back(other);
        }
      }
    }
    ClusterStats stats[2];
    EdgeStats shared;
    bool started[2] = {false, false};
    for (std::uint32_t f = 0; f < graph->face_count(); ++f) {
      const int c = cluster[f];
      if (c < 0) continue;
      if (!started[c])
        stats[c] = graph->face_stats(f);
      else
        stats[c].merge(graph->face_stats(f), {});
      started[c] = true;
    }
    for (const DualEdge& e : graph->edges()) {
      const int a = cluster[e.first], b = cluster[e.second];
      if (a < 0 || b < 0) continue;
      if (a == b)
        stats[a].edges += e.shared;
      else
        shared += e.shared;
    }
    // The hierarchy keeps every cluster's statistics about its centroid.
    for (ClusterStats& s : stats) s = s.centred();
    const detail::ModelSelector selector{HierarchyOptions{}};
    for (auto _ : state) {
      const ClusterView merged(stats[0], stats[1], shared);
      const detail::SelectedModel model = selector.select(merged);
      benchmark::DoNotOptimize(model.cost);
    }
    state.counters["cluster_faces"] = benchmark::Counter(double(faces));
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
  HierarchyOptions exact_costs;
  exact_costs.exact_costs = true;
  HierarchyOptions all_types;
  all_types.primitives = {PrimitiveType::Plane, PrimitiveType::Cylinder, PrimitiveType::Sphere,
                          PrimitiveType::Cone, PrimitiveType::Torus};
  auto build = [](const std::string& name, const std::string& input,
                  const HierarchyOptions& options) {
    configure(benchmark::RegisterBenchmark(name.c_str(), hierarchy, input, options))->Iterations(1);
  };
  build("hierarchy/fandisk", "fandisk.off", {});
  build("hierarchy/bunny00", "bunny00.off", {});
  build("hierarchy/box_with_hole_uniform_0.01", shape, {});
  build("hierarchy_exact_costs/fandisk", "fandisk.off", exact_costs);
  build("hierarchy_all_types/fandisk", "fandisk.off", all_types);
  // One thread against the default (all cores): whether the second core pays (it did not when a
  // merge's few cheap candidates were shared between cores that share no cache).
  HierarchyOptions one_thread;
  one_thread.threads = 1;
  build("hierarchy_one_thread/fandisk", "fandisk.off", one_thread);
  build("hierarchy_one_thread/bunny00", "bunny00.off", one_thread);
  // The approximate merge order at the tolerance the CLI's help suggests.
  HierarchyOptions batched;
  batched.merge_batch_tolerance = 0.1;
  build("hierarchy_batched/fandisk", "fandisk.off", batched);
  build("hierarchy_batched/bunny00", "bunny00.off", batched);
  build("hierarchy_batched/box_with_hole_uniform_0.01", shape, batched);
  // Two regions side by side (the approximate order for two cores), on all threads.
  HierarchyOptions regions;
  regions.regions = 2;
  build("hierarchy_regions/fandisk", "fandisk.off", regions);
  build("hierarchy_regions/bunny00", "bunny00.off", regions);
  configure(benchmark::RegisterBenchmark("read_mesh/fandisk", read, "fandisk.off"));
  configure(benchmark::RegisterBenchmark("read_mesh/bunny00", read, "bunny00.off"));
  configure(benchmark::RegisterBenchmark("cut_describe_k30/fandisk", cut_and_describe,
                                         "fandisk.off", std::uint32_t{30}));
  configure(benchmark::RegisterBenchmark("refine_k40/bunny00", refine_level, "bunny00.off",
                                         std::uint32_t{40}));
  for (std::uint32_t faces : {10u, 1000u, 100000u})
    configure(
        benchmark::RegisterBenchmark(("candidate_evaluation/" + std::to_string(faces)).c_str(),
                                     candidate_evaluation, faces))
        ->Unit(benchmark::kNanosecond);
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
