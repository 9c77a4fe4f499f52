#!/usr/bin/env bash
# Pathological but valid inputs, at growing scale: N triangles sharing one edge (a non-manifold
# "book"), a fan of N triangles around one vertex (a flat disc), and one polygon of N vertices:
# a wavy outline (7 lobes, a third of its vertices reflex) and a spiral strip (arms 0.2 apart,
# laps 0.63 apart; its inner wall is reflex and a lap of the loop clips a few ears: the worst
# case of ear clipping, fanned past its budget from about 100,000 vertices). Prints,
# per input, the median over RUNS of wall-clock seconds and peak RSS of `primseg segment` (GNU
# time) writing the labels of one cluster; bytes per triangle; and the median seconds and peak
# RSS of writing the JSON with its border curves at a cluster per face (the book's spine in
# every border, the fan's centre on every curve); and those of `primseg denoise` at the automatic
# level (its noise estimate smooths the whole mesh; the spine and the hub are on every face).
#
#   bench/pathological.sh BUILD_DIR [N...]     (default N: 10000 100000 1000000; RUNS=3)
set -euo pipefail
build=${1:?usage: bench/pathological.sh BUILD_DIR [N...]}
shift
sizes=("${@:-10000 100000 1000000}")
runs=${RUNS:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
generate() {  # kind n file
  python3 - "$1" "$2" "$3" <<'PY'
import math, sys
kind, n, path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
with open(path, "w") as out:
    if kind == "book":  # edge (0,0,0)-(0,0,1), one page per triangle
        out.write("OFF\n%d %d 0\n0 0 0\n0 0 1\n" % (n + 2, n))
        out.writelines("%.9f %.9f 0.5\n" % (math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n)) for i in range(n))
        out.writelines("3 0 1 %d\n" % (i + 2) for i in range(n))
    elif kind in ("polygon", "spiral"):  # one face of n vertices
        if kind == "polygon":
            points = [((1 + 0.3 * math.sin(7 * a)) * math.cos(a), (1 + 0.3 * math.sin(7 * a)) * math.sin(a))
                      for a in (2 * math.pi * i / n for i in range(n))]
        else:
            arm = [0.05 * i for i in range(n // 2)]
            points = [((1.2 + 0.1 * a) * math.cos(a), (1.2 + 0.1 * a) * math.sin(a)) for a in arm]
            points += [((1 + 0.1 * a) * math.cos(a), (1 + 0.1 * a) * math.sin(a)) for a in reversed(arm)]
        out.write("OFF\n%d 1 0\n" % len(points))
        out.writelines("%.12g %.12g 0\n" % p for p in points)
        out.write("%d %s\n" % (len(points), " ".join(map(str, range(len(points))))))
    else:  # fan: centre 0, rim 1..n, closed
        out.write("OFF\n%d %d 0\n0 0 0\n" % (n + 1, n))
        out.writelines("%.9f %.9f 0\n" % (math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n)) for i in range(n))
        out.writelines("3 0 %d %d\n" % (i + 1, (i + 1) % n + 1) for i in range(n))
PY
}
median_of_runs() {  # command...: prints "seconds peak_rss_kb", the median run by time
  local samples=()
  for ((r = 0; r < runs; ++r)); do
    samples+=("$(/usr/bin/time -f "%e %M" "$@" 2>&1 >/dev/null | tail -1)")
  done
  printf "%s\n" "${samples[@]}" | sort -n | sed -n "$(((runs + 1) / 2))p"
}
printf "%-7s %9s %10s %12s %14s %13s %15s %13s %15s\n" input n seconds peak_rss_MB \
  bytes_per_tri borders_sec borders_rss_MB denoise_sec denoise_rss_MB
for n in ${sizes[@]}; do
  for kind in book fan polygon spiral; do
    file=$work/$kind-$n.off
    generate "$kind" "$n" "$file"
    read -r seconds rss_kb <<<"$(median_of_runs "$build/primseg" segment "$file" -q --clusters 1 \
      --labels "$work/out.labels")"
    faces=$([[ $kind == polygon || $kind == spiral ]] && echo 1 || echo "$n")
    read -r borders_seconds borders_kb <<<"$(median_of_runs "$build/primseg" segment "$file" -q \
      --clusters "$faces" --json "$work/out.json")"
    read -r denoise_seconds denoise_kb <<<"$(median_of_runs "$build/primseg" denoise "$file" -q \
      --clusters auto -o "$work/out.off")"
    printf "%-7s %9d %10s %12d %14d %13s %15d %13s %15d\n" "$kind" "$n" "$seconds" \
      $((rss_kb / 1024)) $((rss_kb * 1024 / n)) "$borders_seconds" $((borders_kb / 1024)) \
      "$denoise_seconds" $((denoise_kb / 1024))
  done
done
