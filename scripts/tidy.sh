#!/usr/bin/env bash
# clang-tidy (.clang-tidy's checks, warnings as errors) on the files kept clean: the mesh readers
# and writers, file I/O and the CLI. Uses the compile commands of BUILD_DIR (default build).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
cmake -S . -B "$build" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON >/dev/null
run-clang-tidy -quiet -j "$(nproc)" -p "$build" 'src/mesh_io/.*\.cpp$' 'src/file_io\.cpp$' \
  'apps/.*\.cpp$'
