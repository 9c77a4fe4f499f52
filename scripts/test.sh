#!/usr/bin/env bash
# Installs what is missing, builds everything (Release, warnings as errors) and runs the whole
# test suite with CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
build=${PRIMSEG_BUILD_DIR:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPRIMSEG_WERROR=ON "$@" >/dev/null
cmake --build "$build"
# PRIMSEG_CTEST_ARGS: extra CTest arguments, e.g. "-E python.pytest".
read -r -a ctest_args <<<"${PRIMSEG_CTEST_ARGS:-}"
ctest --test-dir "$build" --output-on-failure -j "$(nproc)" "${ctest_args[@]}"
