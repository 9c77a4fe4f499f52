#!/usr/bin/env bash
# Browser tests of `primseg view`: installs the web dependencies (npm ci), builds the CLI with the
# viewer embedded, runs web/test/ in Debian's chromium (headless; a missing browser is a
# failure), then prints the viewer's figures on bunny00 and a generated 1M-face mesh
# (PRIMSEG_WEB_BENCH=0 skips them).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
build=${PRIMSEG_BUILD_DIR:-build}
(cd web && npm ci --no-audit --no-fund --loglevel=error)
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPRIMSEG_WERROR=ON >/dev/null
cmake --build "$build" --target primseg_cli primseg_write_stick_figure
export PRIMSEG="$PWD/$build/primseg" PRIMSEG_WEB_ARTIFACTS="$PWD/$build/web-artifacts"
export PRIMSEG_STICK_FIGURE="$PWD/$build/tests/primseg_write_stick_figure"
node --test web/test/
echo "screenshots: $PRIMSEG_WEB_ARTIFACTS"
if [[ ${PRIMSEG_WEB_BENCH:-1} != 0 ]]; then
  data=$(mktemp -d)
  tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -C "$data" data/meshes/bunny00.off
  node web/bench/viewer-bench.mjs "$data/data/meshes/bunny00.off" torus1m
fi
