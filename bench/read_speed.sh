#!/usr/bin/env bash
# Input reading throughput (issue 3: binary PLY and STL at 200 MB/s or more, ascii OFF and OBJ at
# 60 MB/s or more): bunny00 midpoint-subdivided twice (1,206,528 faces) written in each format,
# and bunny00.off as shipped. Each figure is the median over RUNS fresh processes of read_mesh's
# wall-clock time (primseg_bench_memory --read-only): a fresh process meets the page faults of its
# arrays as `primseg` does, which a loop of reads in one process hides (its allocator reuses the
# pages). The file is in the page cache (the first run reads it once before timing).
#
#   bench/read_speed.sh [BUILD_DIR]     (default BUILD_DIR: <repo>/build-bench)
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$repo/build-bench}
runs=${RUNS:-7}
if [[ ! -f $build/build.ninja ]]; then
  cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >&2
fi
ninja -C "$build" primseg_bench_memory primseg_subdivide >&2
data=${TMPDIR:-/tmp}/primseg-read-speed
mkdir -p "$data"
tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -C "$data" data/meshes/bunny00.off
bunny=$data/data/meshes/bunny00.off
inputs=("$bunny")
for format in ply stl off obj; do
  out=$data/bunny00-x16.$format
  # PLY and STL are written binary (little-endian), OFF and OBJ as text.
  [[ -f $out ]] || "$build/bench/primseg_subdivide" "$bunny" "$out" --midpoint 2 >&2
  inputs+=("$out")
done

python3 - "$build/bench/primseg_bench_memory" "$runs" "${inputs[@]}" <<'PY'
import os, statistics, subprocess, sys

bench, runs, inputs = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
target = {"ply": 200, "stl": 200, "off": 60, "obj": 60}
print("| input | format | faces | MB | read (median of %d fresh processes) | MB/s | issue 3 asks |"
      % runs)
print("|---|---|---:|---:|---:|---:|---:|")
for path in inputs:
    kind = path.rsplit(".", 1)[1]
    fields = {}
    times = []
    for run in range(runs + 1):
        line = subprocess.run([bench, path, "--read-only"], check=True, capture_output=True,
                              text=True).stdout
        fields = dict(kv.split("=", 1) for kv in line.split() if "=" in kv)
        if run > 0:  # the first run only brings the file into the page cache
            times.append(float(fields["read_seconds"]))
    seconds = statistics.median(times)
    megabytes = os.path.getsize(path) / 1e6
    binary = kind in ("ply", "stl")
    print(f"| {os.path.basename(path)} | {kind.upper()} {'binary' if binary else 'ascii'} "
          f"| {int(fields['faces']):,} | {megabytes:.1f} | {seconds * 1e3:.0f} ms "
          f"| {megabytes / seconds:.0f} | >= {target[kind]} |")
PY
