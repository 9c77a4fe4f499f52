#!/usr/bin/env bash
# Optional check, not part of CI (Blender is 180 Debian packages): Blender's own glTF importer and
# skinning pose `primseg skeleton --gltf` rigs as `primseg deform` does. Installs Debian's blender
# when missing (root), builds the CLI, then checks man.off (libcgal-demo, 20 bones, four joints
# turned) and the generated stick figure (8 bones, shoulder and elbow nested) with
# tests/tools/blender_pose_check.py. Exits non-zero on the first difference above 1e-5 of a size.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
if ! command -v blender >/dev/null; then
  [[ $(id -u) -eq 0 ]] || { echo "needs Debian's blender (apt-get install blender)" >&2; exit 1; }
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends blender >/dev/null
fi
build=${PRIMSEG_BUILD_DIR:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target primseg_cli primseg_write_stick_figure >/dev/null
primseg="$PWD/$build/primseg"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -C "$work" data/meshes/man.off
"$build/tests/primseg_write_stick_figure" "$work/figure.off"

# check NAME MESH SKELETON_OPTIONS... -- POSE_JSON
check() {
  local name=$1 mesh=$2 pose=$3
  shift 3
  "$primseg" skeleton "$mesh" "$@" -o "$work/$name.json" --gltf "$work/$name.glb" -q
  echo "$pose" >"$work/$name-pose.json"
  "$primseg" deform "$mesh" "$work/$name.json" "$work/$name-pose.json" -o "$work/$name-posed.off" -q
  local status=0
  blender -b --python tests/tools/blender_pose_check.py -- "$work/$name.glb" "$work/$name.json" \
    "$work/$name-pose.json" "$work/$name-posed.off" >"$work/$name.log" 2>&1 || status=$?
  echo "$name:"
  grep -E '^(armature|Blender vs|Traceback|AssertionError)' "$work/$name.log" || cat "$work/$name.log"
  return "$status"
}
check man "$work/data/meshes/man.off" \
  '{"rotations": [{"joint": 2, "axis": [0, 1, 0], "degrees": 70}, {"joint": 4, "axis": [1, 0, 0], "degrees": -45}, {"joint": 1, "axis": [0.3, 0.2, 1], "degrees": 30}, {"joint": 3, "axis": [1, 1, 0], "degrees": 25}]}' \
  --clusters 20
# The figure's joints at K = 8 (cylinders and spheres): 0 left shoulder, 1 left elbow, 4 right
# elbow, 5 right hip (tests/support/stick_figure.hpp).
check figure "$work/figure.off" \
  '{"rotations": [{"joint": 0, "axis": [0.2, 1, 0.3], "degrees": 35}, {"joint": 1, "axis": [0, 1, 0], "degrees": -50}, {"joint": 4, "axis": [0.5, -1, 2], "degrees": 70.5}, {"joint": 5, "axis": [1, 1, 0], "degrees": 20}]}' \
  --clusters 8 --primitives cylinder,sphere
echo "Blender poses both rigs as primseg deform does"
