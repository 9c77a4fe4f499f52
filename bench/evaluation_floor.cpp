// The floor of the exact merge order: how long a build takes when its candidate evaluations cost
// nothing. Each run builds the tree as primseg does (timed), builds it again recording every
// evaluation's outcome (src/evaluation_tape.hpp; untimed), then a third time handing out the
// recorded outcomes instead of evaluating (timed): that build still makes the dual graph, relinks,
// keeps the queue, fits and sums each merged cluster and writes the tree. Its tree must be the
// first one, byte for byte, or the tool fails. On one thread (the tape follows the evaluations'
// order), default options but for the primitive types (--primitives, default
// plane,cylinder,sphere).
//
//   primseg_bench_evaluation_floor MESH_FILE [--runs R] [--primitives LIST]
//   primseg_bench_evaluation_floor --cgal NAME [--runs R] [--primitives LIST]
//   primseg_bench_evaluation_floor --shape NAME [EDGE_LENGTH] [--runs R] [--primitives LIST]
//
// Prints one line of key=value pairs: the medians over R runs (default 5) of the real build
// (build_seconds, with build_setup_seconds for the builder's constructor and build_merge_seconds
// for the merge loop) and of the replaying build (floor_seconds, floor_setup_seconds,
// floor_merge_seconds), the evaluations per build, and evaluation_share = 1 − floor / build.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_support.hpp"
#include "evaluation_tape.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/tree_io.hpp"

namespace {

using Mode = primseg::detail::EvaluationTape::Mode;

int usage() {
  std::fprintf(stderr,
               "usage: primseg_bench_evaluation_floor MESH_FILE [OPTIONS]\n"
               "       primseg_bench_evaluation_floor --cgal NAME [OPTIONS]\n"
               "       primseg_bench_evaluation_floor --shape NAME [EDGE_LENGTH] [OPTIONS]\n"
               "OPTIONS: --runs R --primitives LIST\n");
  return 2;
}

struct Build {
  double setup_seconds = 0, merge_seconds = 0;
  std::uint64_t evaluations = 0;
  primseg::Hierarchy tree;
};

Build build(const std::shared_ptr<const primseg::Mesh>& mesh, primseg::HierarchyOptions options,
            Mode mode) {
  options.threads = 1;
  auto& tape = primseg::detail::evaluation_tape;
  tape.mode = mode;
  tape.next = 0;
  if (mode == Mode::Record) tape.outcomes.clear();
  const auto start = std::chrono::steady_clock::now();
  primseg::HierarchyBuilder builder(mesh, options);
  const auto built = std::chrono::steady_clock::now();
  primseg::Hierarchy tree = builder.finish();
  const auto merged = std::chrono::steady_clock::now();
  tape.mode = Mode::Off;
  if (mode == Mode::Replay && tape.next != tape.outcomes.size())
    throw std::runtime_error("the replaying build left recorded evaluations unused");
  return {std::chrono::duration<double>(built - start).count(),
          std::chrono::duration<double>(merged - built).count(), builder.evaluation_count(),
          std::move(tree)};
}

// The two timed builds by name, so that a profiler can take one alone (valgrind
// --toggle-collect='*replaying_build*', perf report --parent=replaying_build).
[[gnu::noinline]] Build evaluating_build(const std::shared_ptr<const primseg::Mesh>& mesh,
                                         const primseg::HierarchyOptions& options) {
  return build(mesh, options, Mode::Off);
}
[[gnu::noinline]] Build replaying_build(const std::shared_ptr<const primseg::Mesh>& mesh,
                                        const primseg::HierarchyOptions& options) {
  return build(mesh, options, Mode::Replay);
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

int run(int argc, char** argv) {
  using namespace primseg;
  bench::InputArgument input;
  unsigned runs = 5;
  HierarchyOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--runs" && i + 1 < argc) {
      runs = bench::count_argument(arg, argv[++i], 1, 1000, "run");
    } else if (arg == "--primitives" && i + 1 < argc) {
      options.primitives = bench::primitives_argument(arg, argv[++i]);
    } else if (!input.take(argc, argv, i)) {
      return usage();
    }
  }
  if (input.kind == bench::InputArgument::Kind::None) return usage();
  const auto mesh = std::make_shared<const Mesh>(input.load());

  std::vector<double> build_setup, build_merge, build_total, floor_setup, floor_merge, floor_total;
  std::uint64_t evaluations = 0;
  for (unsigned run = 0; run < runs; ++run) {
    const Build real = evaluating_build(mesh, options);
    build(mesh, options, Mode::Record);
    const Build replayed = replaying_build(mesh, options);
    if (serialize_tree(replayed.tree) != serialize_tree(real.tree))
      throw std::runtime_error("the replaying build made another tree than the real one");
    evaluations = real.evaluations;
    build_setup.push_back(real.setup_seconds);
    build_merge.push_back(real.merge_seconds);
    build_total.push_back(real.setup_seconds + real.merge_seconds);
    floor_setup.push_back(replayed.setup_seconds);
    floor_merge.push_back(replayed.merge_seconds);
    floor_total.push_back(replayed.setup_seconds + replayed.merge_seconds);
  }
  std::printf(
      "input=%s faces=%u runs=%u evaluations=%llu build_seconds=%.4f build_setup_seconds=%.4f "
      "build_merge_seconds=%.4f floor_seconds=%.4f floor_setup_seconds=%.4f "
      "floor_merge_seconds=%.4f evaluation_share=%.3f\n",
      input.name.c_str(), mesh->face_count(), runs, static_cast<unsigned long long>(evaluations),
      median(build_total), median(build_setup), median(build_merge), median(floor_total),
      median(floor_setup), median(floor_merge), 1 - median(floor_total) / median(build_total));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return primseg::bench::main_reporting_errors("primseg_bench_evaluation_floor", run, argc, argv);
}
