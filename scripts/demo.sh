#!/usr/bin/env bash
# Installs what is missing, builds primseg (Release), and segments the fandisk model shipped by
# Debian's libcgal-demo: outputs in out/ (labels, JSON, coloured PLY, border curves as OBJ, tree,
# PNG) and a summary.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON >/dev/null  # as test.sh
cmake --build build --target primseg_cli
mkdir -p out
tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -C out --strip-components=2 data/meshes/fandisk.off
./build/primseg segment out/fandisk.off --clusters 30 --labels out/fandisk.labels \
  --json out/fandisk.json --colored out/fandisk.ply --borders out/fandisk-borders.obj \
  --tree out/fandisk.tree --png out/fandisk.png
echo "outputs: $(ls out | tr '\n' ' ')"
