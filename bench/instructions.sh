#!/usr/bin/env bash
# Prints the instruction counts of the whole hierarchy as a Markdown table (see bench/README.md):
# figures that do not depend on the host's speed or load, unlike bench/figures.sh's times.
#
#   bench/instructions.sh [--profile N] [BUILD_DIR]     (default BUILD_DIR <repo>/build-bench)
#
# For fandisk, bunny00 and the uniform box_with_hole (edge 1% of the diagonal), each in the exact
# merge order and with --merge-batch-tolerance 0.1, runs primseg_bench_memory on one thread under
# valgrind's callgrind, counting the instructions of the build alone (its function
# build_and_destroy_tree: the dual graph, every candidate and merge, and destroying the tree; not
# reading the input). One run each: on one thread the count is the same from run to run, and the
# candidate evaluations (HierarchyBuilder::evaluation_count()) are the same on any machine.
# --profile N also prints each build's N costliest functions (callgrind_annotate: the
# instructions in each function itself, not in what it calls). BENCH_ARGS adds options to every run, for example
# BENCH_ARGS="--exact-costs". About 3 minutes on 2 cores once built; needs valgrind.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
profile=0
if [[ ${1:-} == --profile ]]; then
  [[ $# -ge 2 && $2 =~ ^[0-9]+$ ]] || { echo "usage: $0 [--profile N] [BUILD_DIR]" >&2; exit 2; }
  profile=$2
  shift 2
fi
build=${1:-$repo/build-bench}
command -v valgrind >/dev/null || { echo "$0: needs valgrind (apt-get install valgrind)" >&2; exit 1; }
if [[ ! -f $build/build.ninja ]]; then
  echo "== configuring $build (Release)" >&2
  cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >&2
fi
ninja -C "$build" primseg_bench_memory >&2
commit="$(git -C "$repo" rev-parse --short HEAD)$(git -C "$repo" diff --quiet HEAD -- src include \
  || echo ' + uncommitted changes in src/ or include/')"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

inputs=("--cgal fandisk.off" "--cgal bunny00.off" "--shape box_with_hole 0.01")
labels=("fandisk.off" "bunny00.off" "box_with_hole, uniform, edge 1%")
orders=("" "--merge-batch-tolerance 0.1")
# Runs one build under callgrind: its figures line to $out/$1.txt, its callgrind file to $out/$1.out.
measure() {
  local name=$1
  shift
  # shellcheck disable=SC2068  # the input and options are several words on purpose
  valgrind --tool=callgrind --toggle-collect='*build_and_destroy_tree*' \
    --callgrind-out-file="$out/$name.out" "$build/bench/primseg_bench_memory" $@ --threads 1 \
    >"$out/$name.txt" 2>"$out/$name.log" || { cat "$out/$name.log" >&2; touch "$out/$name.failed"; }
}
runs=()
for i in "${!inputs[@]}"; do
  for j in "${!orders[@]}"; do
    runs+=("$i-$j")
    echo "== ${inputs[$i]} ${orders[$j]} ${BENCH_ARGS:-}" >&2
    # shellcheck disable=SC2086
    measure "$i-$j" ${inputs[$i]} ${orders[$j]} ${BENCH_ARGS:-} &
    # Two at a time: instruction counts do not depend on the load.
    if (($(jobs -rp | wc -l) >= 2)); then wait -n; fi
  done
done
wait
if compgen -G "$out/*.failed" >/dev/null; then
  echo "$0: a build failed (its valgrind log is above)" >&2
  exit 1
fi

# Runs, input labels and merge orders go to Python one list per line.
lines() { printf '%s\n' "$@"; }
python3 - "$out" "$commit" "${BENCH_ARGS:-}" "$(lines "${runs[@]}")" "$(lines "${labels[@]}")" \
  "$(lines "${orders[@]}")" <<'PY'
import re, sys

out, commit, extra = sys.argv[1:4]
runs, labels, orders = (arg.split("\n") for arg in sys.argv[4:7])
print("| input | faces | merge order | evaluations / face | instructions (M) | instructions / face "
      "| instructions / evaluation |")
print("|---|---:|---|---:|---:|---:|---:|")
for run in runs:
    with open(f"{out}/{run}.txt") as f:
        fields = dict(kv.split("=", 1) for kv in f.read().split() if "=" in kv)
    with open(f"{out}/{run}.out") as f:
        totals = re.search(r"^totals:\s*(\d+)", f.read(), re.M)
    if totals is None:
        sys.exit(f"{run}: no instruction total in the callgrind output")
    instructions, faces = int(totals.group(1)), int(fields["faces"])
    evaluations = int(fields["evaluations"])
    input_index, order_index = map(int, run.split("-"))
    order = f"`{orders[order_index]}`" if orders[order_index] else "exact"
    print(f"| {labels[input_index]} | {faces:,} | {order} "
          f"| {evaluations / faces:.2f} | {instructions / 1e6:,.0f} | {instructions / faces:,.0f} "
          f"| {instructions / evaluations:,.0f} |")
print()
print(f"(Instructions of the whole build on one thread, valgrind's callgrind; commit {commit}"
      + (f"; options {extra}" if extra else "") + ".)")
PY

if ((profile > 0)); then
  for run in "${runs[@]}"; do
    echo
    order=${orders[${run#*-}]}
    echo "== ${labels[${run%-*}]}, ${order:-exact order}: the $profile costliest functions"
    callgrind_annotate "$out/$run.out" 2>/dev/null | grep -E '^ *[0-9,]+ \(' | sed -n "2,$((profile + 1))p" \
      | cut -c1-160
  done
fi
