#!/usr/bin/env bash
# clang-tidy (.clang-tidy's checks, warnings as errors). Uses the compile commands of BUILD_DIR.
#
#   scripts/tidy.sh [BUILD_DIR]          the mesh readers and writers, file I/O and the CLI (CI;
#                                        about 5 minutes on two cores)
#   scripts/tidy.sh [BUILD_DIR] --all    the whole library too (about 4 minutes more: its files
#                                        include Eigen, whose headers every check walks through)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
case ${2:-} in
  "") files=('src/mesh_io/.*\.cpp$' 'src/file_io\.cpp$' 'apps/.*\.cpp$') ;;
  --all) files=('src/.*\.cpp$' 'apps/.*\.cpp$') ;;
  *) echo "usage: scripts/tidy.sh [BUILD_DIR] [--all]" >&2; exit 2 ;;
esac
cmake -S . -B "$build" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON >/dev/null
run-clang-tidy -quiet -j "$(nproc)" -p "$build" "${files[@]}"
