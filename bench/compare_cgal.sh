#!/usr/bin/env bash
# Side-by-side timings of primseg's full hierarchy and CGAL's region growing and VSA, in one
# process on the same meshes (see bench/README.md, "Comparison with CGAL").
#
#   bench/compare_cgal.sh [--build-dir DIR] [-- PROGRAM ARGS...]
#
# Configures DIR (default <repo>/build-cgal) as a Release build if it has no build.ninja yet,
# builds primseg_compare_cgal (needs Debian's libcgal-dev; about 1.5 min the first time) and runs
# it: Markdown table on stdout, progress on stderr. PROGRAM ARGS go to primseg_compare_cgal
# (default: fandisk.off bunny00.off shape:box_with_hole, 5 repetitions). About 35 s on 2 cores.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$repo/build-cgal
if [[ ${1:-} == --build-dir ]]; then
  [[ $# -ge 2 ]] || { echo "usage: $0 [--build-dir DIR] [-- ARGS...]" >&2; exit 2; }
  build=$2
  shift 2
fi
[[ ${1:-} == -- ]] && shift

if [[ ! -f $build/build.ninja ]]; then
  echo "== configuring $build (Release)" >&2
  cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >&2
fi
build_type=$(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' "$build/CMakeCache.txt")
if [[ $build_type != Release ]]; then
  echo "warning: $build is a '$build_type' build, timings are only meaningful in Release" >&2
fi
if ! grep -q primseg_compare_cgal "$build/build.ninja"; then
  echo "error: no primseg_compare_cgal target in $build: CGAL (libcgal-dev) or Google Benchmark" \
       "(libbenchmark-dev, needed for bench/) was not found at configure time" >&2
  exit 1
fi
echo "== building primseg_compare_cgal" >&2
ninja -C "$build" primseg_compare_cgal >&2

"$build/bench/primseg_compare_cgal" "$@"
echo
echo "Measured: $(git -C "$repo" rev-parse --short HEAD)$(git -C "$repo" diff --quiet HEAD -- src include \
  || echo ' + uncommitted changes in src/ or include/')."
