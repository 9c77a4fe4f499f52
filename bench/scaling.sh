#!/usr/bin/env bash
# Scaling series of the whole hierarchy (plane + sphere + cylinder) from 13k to 1.2M faces, and
# with --large to 10.9M faces (about 5.3 GB of memory and 7.5 minutes a run): median hierarchy time
# of RUNS runs (the CLI's own timing, without reading), peak RSS, bytes per face, faces per
# second, and time / (n log2 n) relative to the smallest input (flat if the growth is n log n).
#
#   bench/scaling.sh [--large] [BUILD_DIR]     (default BUILD_DIR: <repo>/build-bench)
#
# SEGMENT_ARGS adds options to every `primseg segment` run, for example
# SEGMENT_ARGS="--merge-batch-tolerance 0.1" for the approximate merge order.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
large=0
if [[ ${1:-} == --large ]]; then large=1; shift; fi
build=${1:-$repo/build-bench}
runs=${RUNS:-5}
if [[ ! -f $build/build.ninja ]]; then
  cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >&2
fi
ninja -C "$build" primseg_cli primseg_subdivide >&2
data=${TMPDIR:-/tmp}/primseg-scaling
mkdir -p "$data"
tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -C "$data" data/meshes/fandisk.off \
  data/meshes/bunny00.off
meshes=$data/data/meshes
make_input() {  # name, subdivide arguments...
  local out=$data/$1.ply
  shift
  [[ -f $out ]] || "$build/bench/primseg_subdivide" "$meshes/bunny00.off" "$out" "$@" >&2
}
make_input bunny00-x4 --midpoint 1
make_input bunny00-x16 --midpoint 2
inputs=("$meshes/fandisk.off" "$meshes/bunny00.off" "$data/bunny00-x4.ply" "$data/bunny00-x16.ply")
if ((large)); then
  make_input bunny00-x144-noise --midpoint 2 --trisect --noise 0.001
  inputs+=("$data/bunny00-x144-noise.ply")
  runs_large=${RUNS_LARGE:-1}
fi

python3 - "$build/primseg" "$runs" "${runs_large:-1}" "${SEGMENT_ARGS:-}" "${inputs[@]}" <<'PY'
import json, math, os, resource, shlex, statistics, subprocess, sys, tempfile

cli, runs, runs_large = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
extra, inputs = shlex.split(sys.argv[4]), sys.argv[5:]
rows = []
for path in inputs:
    times, peaks = [], []
    for run in range(runs if os.path.getsize(path) < 200e6 else runs_large):
        with tempfile.NamedTemporaryFile(suffix=".json") as out:
            # Each run in its own child, so the peak RSS is that run's alone.
            pid = os.fork()
            if pid == 0:
                os.execv(cli, [cli, "segment", path, "--clusters", "1", "-q", "--json", out.name]
                         + extra)
            _, status, usage = os.wait4(pid, 0)
            if status != 0:
                sys.exit(f"{path}: primseg failed with status {status}")
            report = json.load(open(out.name))
        times.append(report["timing"]["hierarchy_seconds"])
        peaks.append(usage.ru_maxrss * 1024)
        faces = report["mesh"]["faces"]
    t = statistics.median(times)
    rows.append((os.path.basename(path), faces, t, max(peaks), len(times)))
    print(f"{rows[-1][0]}: {faces} faces, {t:.3f} s (median of {len(times)})", file=sys.stderr)

base = rows[0][2] / (rows[0][1] * math.log2(rows[0][1]))
print("| input | faces | hierarchy (median) | faces/s | peak RSS | bytes/face | time / n log n |")
print("|---|---:|---:|---:|---:|---:|---:|")
for name, faces, t, peak, n in rows:
    print(f"| {name} | {faces:,} | {t * 1000:,.0f} ms ({n} runs) | {faces / t:,.0f} | "
          f"{peak / 2**20:,.0f} MB | {peak / faces:,.0f} | "
          f"{t / (faces * math.log2(faces)) / base:.2f} |")
PY
