#!/usr/bin/env bash
# Compares the segmentations of two revisions of primseg: every level that bench/dump_levels.cpp
# writes (fandisk at K = 10 ... 100, every generated shape in its CAD, uniform and noisy
# tessellation at the true K, the noisy ones also at twice it and 20), matched cluster to cluster
# by the Hungarian method on shared face counts. Prints the mean IoU of each level and the worst, and exits non-zero if a
# level's mean IoU is below MIN_IOU (default 0.99): issue 3's rule when a solver changes.
#
#   bench/compare_revisions.sh OLD_REV [NEW_REV]     (NEW_REV default: the working tree)
#
# Each revision is exported with git archive into $TMPDIR and its library built there (Release);
# bench/dump_levels.cpp of this tree is compiled against it (public API only). Needs libcgal-demo
# (fandisk), and Debian's python3 with numpy and scipy (/usr/bin/python3).
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
[[ $# -ge 1 ]] || { echo "usage: $0 OLD_REV [NEW_REV]" >&2; exit 2; }
work=${TMPDIR:-/tmp}/primseg-compare
mkdir -p "$work"
tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -C "$work" data/meshes/fandisk.off
fandisk=$work/data/meshes/fandisk.off

labels_of() {  # revision (empty: working tree) -> prints the labels directory
  local rev=$1 src name
  if [[ -z $rev ]]; then
    src=$repo
    name=worktree
  else
    local sha
    sha=$(git -C "$repo" rev-parse --verify "$rev^{commit}")
    name=${sha:0:12}
    src=$work/src-$name
    if [[ ! -f $src/CMakeLists.txt ]]; then
      rm -rf "$src" && mkdir -p "$src"
      git -C "$repo" archive "$sha" | tar -x -C "$src"
    fi
  fi
  local build=$work/build-$name
  cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPRIMSEG_BUILD_TESTS=OFF \
    -DPRIMSEG_BUILD_BENCH=OFF -DPRIMSEG_BUILD_CLI=OFF -DPRIMSEG_PYTHON=OFF >/dev/null
  ninja -C "$build" primseg >&2
  g++ -O2 -std=c++20 -I"$src/include" -I/usr/include/eigen3 "$repo/bench/dump_levels.cpp" \
    "$build/libprimseg.a" -lpthread -o "$build/dump_levels"
  rm -rf "$work/labels-$name"
  "$build/dump_levels" "$work/labels-$name" "$fandisk"
  echo "$work/labels-$name"
}

old=$(labels_of "$1")
new=$(labels_of "${2:-}")
/usr/bin/python3 - "$old" "$new" "${MIN_IOU:-0.99}" <<'PY'
import os, sys
import numpy as np
from scipy.optimize import linear_sum_assignment

old_dir, new_dir, minimum = sys.argv[1], sys.argv[2], float(sys.argv[3])
rows = []
for name in sorted(os.listdir(old_dir)):
    a = np.loadtxt(os.path.join(old_dir, name), dtype=np.int64)
    b = np.loadtxt(os.path.join(new_dir, name), dtype=np.int64)
    overlap = np.zeros((a.max() + 1, b.max() + 1))
    np.add.at(overlap, (a, b), 1)
    rows_a, cols_b = linear_sum_assignment(-overlap)
    union = overlap.sum(1)[rows_a] + overlap.sum(0)[cols_b] - overlap[rows_a, cols_b]
    iou = overlap[rows_a, cols_b] / union
    # Clusters of the old level left unmatched (none when K is equal) score 0.
    mean = iou.sum() / overlap.shape[0]
    rows.append((name[:-4], mean, (a == a).all() and np.array_equal(a, b)))
worst = min(rows, key=lambda r: r[1])
identical = sum(1 for r in rows if r[2])
for name, mean, same in rows:
    print(f"{name:45s} mean IoU {mean:.4f}{'  (identical)' if same else ''}")
print(f"\n{len(rows)} levels, {identical} identical; mean of means {np.mean([r[1] for r in rows]):.4f}; "
      f"worst {worst[0]} {worst[1]:.4f}")
sys.exit(0 if worst[1] >= minimum else 1)
PY
