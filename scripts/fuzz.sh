#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ (clang, ASan+UBSan) and runs each for a bounded time from
# its committed seed corpus and dictionary. Fails if any target finds a crash, leaving the
# reproducer in $build/artifacts/ (make it a regression test: fuzz/regressions/ and
# tests/mesh_io/).
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET]     (default 45: 9 targets, about 4 minutes on 2 cores)
#   PRIMSEG_FUZZ_BUILD_DIR=build-fuzz        build directory; one already configured with
#                                            PRIMSEG_FUZZ=ON is built as it is (CI fuzzes in its
#                                            sanitizer pass's build, PRIMSEG_FUZZ_COVERAGE=edges)
#   PRIMSEG_FUZZ_JOBS=$(nproc)               targets run at once
#   PRIMSEG_FUZZ_TARGETS="stl tree"          a subset of the targets (default: all nine)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-45}
build=${PRIMSEG_FUZZ_BUILD_DIR:-build-fuzz}
all_targets=" off obj ply stl detect tree skeleton segment tools "
read -ra targets <<<"${PRIMSEG_FUZZ_TARGETS:-$all_targets}"
for target in "${targets[@]}"; do
  if [[ $all_targets != *" $target "* ]]; then
    echo "fuzz.sh: unknown target '$target' (targets:${all_targets% })" >&2
    exit 2
  fi
done
if ! grep -qx 'PRIMSEG_FUZZ:BOOL=ON' "$build/CMakeCache.txt" 2>/dev/null; then
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
    -DPRIMSEG_FUZZ=ON -DPRIMSEG_WERROR=ON -DPRIMSEG_BUILD_TESTS=OFF -DPRIMSEG_BUILD_CLI=OFF \
    -DPRIMSEG_BUILD_BENCH=OFF -DCMAKE_UNITY_BUILD=ON >/dev/null
fi
cmake --build "$build" --target fuzz_targets
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
mkdir -p "$build/artifacts"
# Runs one target into $build/logs/$target.log; libFuzzer is single-threaded, so the targets run
# $jobs at a time (both cores in CI: 9 x 20 s takes 100 s instead of 180 s).
fuzz_one() {
  local target=$1 dict=fuzz/dict/$1.dict binary=$build/fuzz/fuzz_read_$1
  case $target in
    detect) dict=$build/detect.dict ;;
    tree) dict= ;;
    segment | tools) dict= binary=$build/fuzz/fuzz_$1 ;;
  esac
  # New inputs go to a scratch corpus in the build directory, never into the committed seeds.
  local work=$build/corpus/$target
  mkdir -p "$work"
  "$binary" "$work" "fuzz/corpus/$target" ${dict:+-dict="$dict"} -max_total_time="$seconds" \
    -max_len=4096 -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 -print_final_stats=1 \
    -artifact_prefix="$build/artifacts/$target-" >"$build/logs/$target.log" 2>&1 || true
}
jobs=${PRIMSEG_FUZZ_JOBS:-$(nproc)}
cat fuzz/dict/{off,obj,ply,stl}.dict >"$build/detect.dict"
rm -rf "$build/logs" && mkdir -p "$build/logs"
running=0
for target in "${targets[@]}"; do
  if ((running >= jobs)); then
    wait -n
    running=$((running - 1))
  fi
  fuzz_one "$target" &
  running=$((running + 1))
done
wait
status=0
for target in "${targets[@]}"; do
  echo "== fuzz $target: ${seconds} s =="
  grep -E '^(stat::number_of_executed_units|stat::peak_rss_mb|==|SUMMARY|.*ERROR|.*invariant|.*reader returned|.*Test unit written)' \
    "$build/logs/$target.log" || true
  if compgen -G "$build/artifacts/$target-*" >/dev/null; then
    echo "fuzz $target: finding(s) in $build/artifacts/ (log: $build/logs/$target.log)" >&2
    status=1
  fi
done
exit $status
