#!/usr/bin/env bash
# Prints primseg's performance figures as a Markdown table (see bench/README.md).
#
#   bench/figures.sh [BUILD_DIR]               the working tree; default BUILD_DIR <repo>/build-bench
#   bench/figures.sh --commit REV [BUILD_DIR]  a clean `git archive` of REV in the temp dir, built
#                                              there (default BUILD_DIR <export>/build): figures of
#                                              exactly that commit, whatever the tree holds
#
# Configures BUILD_DIR as a Release build if it has no build.ninja yet, brings primseg_bench and
# primseg_bench_memory up to date (ninja), lets them extract fandisk.off and bunny00.off from
# Debian's libcgal-demo archive into the temp dir, runs the timings (5 repetitions each) and one
# peak-memory run per input, then prints the table on stdout. Progress and the raw Google
# Benchmark console output go to stderr; the raw JSON is kept in BUILD_DIR/bench-figures-N.json.
# About 1.5 minutes on 2 cores once built. RUNS=N (default 1) repeats the timings and the memory
# runs N times and reports, per row, the median of the N runs' medians (and of their peaks), with
# each run's median in the footer: a noisy host's figures from one command.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_default=$repo/build-bench
if [[ ${1:-} == --commit ]]; then
  [[ $# -ge 2 ]] || { echo "usage: $0 [--commit REV] [BUILD_DIR]" >&2; exit 2; }
  sha=$(git -C "$repo" rev-parse --verify "$2^{commit}")
  export_dir=${TMPDIR:-/tmp}/primseg-figures-${sha:0:12}
  if [[ ! -f $export_dir/CMakeLists.txt ]]; then
    echo "== exporting $sha to $export_dir" >&2
    rm -rf "$export_dir.partial" && mkdir -p "$export_dir.partial"
    git -C "$repo" archive "$sha" | tar -x -C "$export_dir.partial"
    rm -rf "$export_dir" && mv "$export_dir.partial" "$export_dir"
  fi
  repo=$export_dir
  build_default=$export_dir/build
  commit=${sha:0:7}
  shift 2
else
  commit="$(git -C "$repo" rev-parse --short HEAD)$(git -C "$repo" diff --quiet HEAD -- src include \
    || echo ' + uncommitted changes in src/ or include/')"
fi
build=${1:-$build_default}
runs=${RUNS:-1}
if ! [[ $runs =~ ^[1-9][0-9]*$ ]]; then
  echo "$0: RUNS must be a positive integer, not '$runs'" >&2
  exit 2
fi

if [[ ! -f $build/build.ninja ]]; then
  echo "== configuring $build (Release)" >&2
  cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >&2
fi
build_type=$(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' "$build/CMakeCache.txt")
if [[ $build_type != Release ]]; then
  echo "warning: $build is a '$build_type' build, figures are only meaningful in Release" >&2
fi
echo "== building primseg_bench primseg_bench_memory" >&2
ninja -C "$build" primseg_bench primseg_bench_memory >&2

for ((run = 1; run <= runs; ++run)); do
  json=$build/bench-figures-$run.json
  memory=$build/bench-figures-memory-$run.txt
  echo "== run $run of $runs: timings (load average: $(cut -d' ' -f1-3 /proc/loadavg))" >&2
  "$build/bench/primseg_bench" --benchmark_out="$json" --benchmark_out_format=json >&2

  echo "== run $run of $runs: peak memory" >&2
  : >"$memory"
  for input in "--cgal fandisk.off" "--cgal bunny00.off" "--shape box_with_hole 0.01" \
               "--cgal fandisk.off --exact-costs" "--cgal fandisk.off --regions 2" \
               "--cgal bunny00.off --regions 2"; do
    # shellcheck disable=SC2086  # the input is several words on purpose
    echo "$input $("$build/bench/primseg_bench_memory" $input)" | tee -a "$memory" >&2
  done
done

python3 - "$build" "$runs" "$commit" "$(cut -d' ' -f1-3 /proc/loadavg)" <<'PY'
import json, statistics, sys

build, runs, commit, load = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
reports = []
for run in range(1, runs + 1):
    with open(f"{build}/bench-figures-{run}.json") as f:
        reports.append(json.load(f))

def aggregate_of(report, prefix, name):
    """The `name` aggregate (median, cv, ...) of the benchmark whose run_name starts with prefix,
    in one run's report."""
    for b in report["benchmarks"]:
        if b.get("run_type") == "aggregate" and b["run_name"].startswith(prefix) \
                and b["aggregate_name"] == name:
            if b.get("error_occurred"):
                sys.exit(f"{prefix}: {b.get('error_message')}")
            return b
    for b in report["benchmarks"]:
        if b["run_name"].startswith(prefix) and b.get("error_occurred"):
            sys.exit(f"{prefix}: {b.get('error_message')}")
    return None

def aggregate(prefix, name):
    """The `name` aggregate of every run (None if a run lacks it): one per run."""
    found = [aggregate_of(report, prefix, name) for report in reports]
    return None if any(b is None for b in found) else found

def ms(b, key="real_time"):
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
    return b[key] * scale

peaks = {}  # input -> peak RSS of each run
for run in range(1, runs + 1):
    with open(f"{build}/bench-figures-memory-{run}.txt") as f:
        for line in f:
            fields = dict(kv.split("=", 1) for kv in line.split() if "=" in kv)
            peaks.setdefault(line.split("input=")[0].strip(), []).append(int(fields["peak_rss"]))

def median_ms(found, key="real_time"):
    return statistics.median(ms(b, key) for b in found)

rows = [
    ("fandisk.off", "hierarchy/fandisk/", "read_mesh/fandisk/", "--cgal fandisk.off"),
    ("bunny00.off", "hierarchy/bunny00/", "read_mesh/bunny00/", "--cgal bunny00.off"),
    ("box_with_hole (Uniform, edge 0.01)", "hierarchy/box_with_hole_uniform_0.01/", None,
     "--shape box_with_hole 0.01"),
    ("fandisk.off, `exact_costs` (reference mode)", "hierarchy_exact_costs/fandisk/", None,
     "--cgal fandisk.off --exact-costs"),
    ("fandisk.off, one thread (`--threads 1`)", "hierarchy_one_thread/fandisk/", None, None),
    ("bunny00.off, one thread", "hierarchy_one_thread/bunny00/", None, None),
    ("fandisk.off, all five types (plane, cylinder, sphere, cone, torus)",
     "hierarchy_all_types/fandisk/", None, None),
    ("fandisk.off, `--merge-batch-tolerance 0.1` (approximate order)",
     "hierarchy_batched/fandisk/", None, None),
    ("bunny00.off, `--merge-batch-tolerance 0.1`", "hierarchy_batched/bunny00/", None, None),
    ("box_with_hole, `--merge-batch-tolerance 0.1`",
     "hierarchy_batched/box_with_hole_uniform_0.01/", None, None),
    ("fandisk.off, `--regions 2` (approximate order, two cores)", "hierarchy_regions/fandisk/",
     None, "--cgal fandisk.off --regions 2"),
    ("bunny00.off, `--regions 2`", "hierarchy_regions/bunny00/", None,
     "--cgal bunny00.off --regions 2"),
]

of = "median of 5" if runs == 1 else f"median of {runs} runs' medians of 5"
print(f"| input | faces | full hierarchy, {of} (ms) | faces/s | peak RSS (MB) "
      "| bytes/face | read_mesh (MB/s) |")
print("|---|---:|---:|---:|---:|---:|---:|")
notes = []
for label, hierarchy, read, mem in rows:
    median, cv = aggregate(hierarchy, "median"), aggregate(hierarchy, "cv")
    if median is None:
        continue
    faces = int(median[0]["faces"])
    time = median_ms(median)
    peak = statistics.median(peaks.get(mem, [0])) if mem else 0
    read_cell = "–"
    if read:
        r = aggregate(read, "median")
        if r is not None:
            rate = statistics.median(b["bytes_per_second"] for b in r)
            read_cell = f"{rate / 1e6:.0f} ({median_ms(r):.2f} ms)"
    print(f"| {label} | {faces:,} | {time:,.0f} | {faces / (time / 1e3):,.0f} "
          f"| {f'{peak / 1e6:.1f}' if peak else '–'} | {f'{peak / faces:,.0f}' if peak else '–'} "
          f"| {read_cell} |")
    spread = (f"CV {100 * cv[0]['real_time']:.0f}%" if runs == 1 else
              "runs' medians " + ", ".join(f"{ms(b):,.0f}" for b in median) + " ms")
    notes.append(f"{label.split(',')[0].split(' (')[0]}"
                 f"{' exact' if 'exact' in hierarchy else ''}"
                 f"{' all types' if 'all_types' in hierarchy else ''}"
                 f"{' one thread' if 'one_thread' in hierarchy else ''}"
                 f"{' batched' if 'batched' in hierarchy else ''}"
                 f"{' regions' if 'regions' in hierarchy else ''}: "
                 f"CPU {median_ms(median, 'cpu_time'):,.0f} ms, {spread}")

cut = aggregate("cut_describe_k30/fandisk/", "median")
print()
if cut is not None:
    print(f"`cut_by_count` + `describe_clusters` at K = 30 on fandisk.off: "
          f"{median_ms(cut):.2f} ms ({of}).")
refined = aggregate("refine_k40/bunny00/", "median")
if refined is not None:
    print(f"`refine_boundaries` (5 passes) at K = 40 on bunny00.off: "
          f"{median_ms(refined):.0f} ms ({of}).")
print()
ctx = reports[-1]["context"]
each = ("coefficient of variation of the 5 runs" if runs == 1 else
        "each run's median wall-clock time")
print(f"Commit {commit}, Release, {ctx['num_cpus']} × {ctx['mhz_per_cpu']} MHz, "
      f"load average {load} at the end. Wall-clock times; per hierarchy, median CPU time and "
      f"{each}: " + "; ".join(notes) + ".")
PY
