#!/usr/bin/env bash
# Which lines of the library and the CLI the whole test suite runs: clang's source-based coverage
# (llvm-cov), a table per file of src/, apps/ and include/, or the lines of one file never run.
#
#   scripts/coverage.sh [BUILD_DIR]                  build, run every test, print the table
#   scripts/coverage.sh --table [BUILD_DIR]          the table again, from the last run's profile
#   scripts/coverage.sh --show FILE [BUILD_DIR]      the lines of FILE (e.g. src/mesh_io/read_ply.cpp)
#                                                    that no test ran, from the last run's profile
#
# BUILD_DIR defaults to build-coverage (clang++, -O1, a unity build). About 20 minutes on two cores;
# the dependencies are scripts/test.sh's (scripts/install-deps.sh), with clang and llvm. Functions
# evaluated at compile time (constexpr tables) show as never run; so do the paths of system
# failures (EINTR, a full disk) and the 32-bit limits.
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: $0 [--table | --show FILE] [BUILD_DIR]"
show="" rerun=1
if [[ ${1:-} == --show ]]; then
  [[ $# -ge 2 ]] || { echo "$usage" >&2; exit 2; }
  show=$2 rerun=0
  shift 2
elif [[ ${1:-} == --table ]]; then
  rerun=0
  shift
fi
build=${1:-build-coverage}
if [[ $# -gt 1 || $build == -* ]]; then
  echo "$usage" >&2
  exit 2
fi
for tool in clang++ llvm-profdata llvm-cov; do
  command -v "$tool" >/dev/null || { echo "$0: needs $tool (apt-get install clang llvm)" >&2; exit 1; }
done
build=$(realpath -m "$build")
profile=$build/coverage.profdata
if ((rerun)); then
  if [[ ! -f $build/build.ninja ]]; then
    cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -DNDEBUG" \
      -DCMAKE_CXX_FLAGS="-fprofile-instr-generate -fcoverage-mapping" \
      -DCMAKE_EXE_LINKER_FLAGS="-fprofile-instr-generate" \
      -DCMAKE_SHARED_LINKER_FLAGS="-fprofile-instr-generate" \
      -DPRIMSEG_BUILD_BENCH=OFF -DPRIMSEG_PYTHON=OFF -DCMAKE_UNITY_BUILD=ON >&2
  fi
  ninja -C "$build" >&2
  rm -rf "$build/profiles" "$profile"
  mkdir -p "$build/profiles"
  # One raw profile per process (%p) and binary (%m): the CLI tests run primseg many times at once.
  LLVM_PROFILE_FILE="$build/profiles/%p-%m.profraw" ctest --test-dir "$build" \
    -j"$(nproc)" --output-on-failure >&2
  # The interruption tests kill primseg with SIGKILL, which can leave a profile half written:
  # llvm-profdata warns about it and merges the others.
  llvm-profdata merge -sparse -failure-mode=all "$build"/profiles/*.profraw -o "$profile"
elif [[ ! -f $profile ]]; then
  echo "$0: no profile in $build yet: run scripts/coverage.sh $build first" >&2
  exit 1
fi
# The CLI and every test program: together they hold all the library code the tests ran.
coverage=("$build/primseg" -instr-profile="$profile")
for binary in "$build"/tests/primseg_test_*; do
  if [[ -f $binary && -x $binary ]]; then coverage+=(-object "$binary"); fi
done
# Not the tests' own code, system headers, nor the viewer page embedded as one string literal.
coverage+=(-ignore-filename-regex="^($PWD/(tests|fuzz|bench)/|/usr/)|viewer_bundle")
# A function compiled into several test programs (each a unity build of its own) has one record
# per program, which llvm-cov warns about and merges: the warning is left out.
quiet() { "$@" 2> >(grep -v 'functions have mismatched data' >&2); }
if [[ -n $show ]]; then
  [[ -f $show ]] || { echo "$0: no file '$show' (give it relative to the repository)" >&2; exit 2; }
  # Only the lines with a count of zero, numbered as in the file.
  annotated=$(quiet llvm-cov show "${coverage[@]}" "$PWD/$show")
  grep -E '^ *[0-9]+\| *0\|' <<<"$annotated" || echo "every line of $show ran"
else
  quiet llvm-cov report "${coverage[@]}"
fi
