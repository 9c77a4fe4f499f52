"""Blender's glTF importer and skinning against `primseg deform` (scripts/check-gltf-blender.sh).

Run by Blender, headless:
    blender -b --python blender_pose_check.py -- RIG.glb SKELETON.json POSE.json POSED.off

Imports RIG.glb (`primseg skeleton --gltf`), checks that the armature has a bone per skin joint and
the mesh a vertex group per bone, sets the pose file's rotations on the bones whose extras name the
rotated joints (parents first, each axis in its parent's rest frame, as pose files define them),
and compares the skinned vertices Blender evaluates with POSED.off, written by `primseg deform` for
the same pose. Exits 1 when any vertex differs by more than 1e-5 of the mesh's size.
"""

import json
import math
import sys

import bpy
import numpy
from mathutils import Matrix, Vector

# Debian 12's Blender 3.4 glTF importer still uses numpy.bool, which numpy 1.24 removed.
if "bool" not in numpy.__dict__:
    numpy.bool = bool

rig, skeleton_path, pose_path, posed_path = sys.argv[sys.argv.index("--") + 1:]
skeleton = json.load(open(skeleton_path))
rotations = json.load(open(pose_path))["rotations"]

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=rig)
armature = next(o for o in bpy.data.objects if o.type == "ARMATURE")
mesh = next(o for o in bpy.data.objects if o.type == "MESH")
ends = sum(joint["kind"] == "virtual" for joint in skeleton["joints"])
bones = len(skeleton["bones"])
print(f"armature: {len(armature.data.bones)} bones; mesh: {len(mesh.vertex_groups)} vertex groups")
assert len(armature.data.bones) == bones + ends, "a bone per skin joint"
assert {g.name for g in mesh.vertex_groups} >= {f"bone_{b}" for b in range(bones)}

# glTF is Y up, Blender Z up: the importer maps (x, y, z) to (x, -z, y).
to_blender = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))
world = armature.matrix_world.inverted() @ to_blender  # primseg's coordinates -> armature space


def hanging_bone(joint):
    found = [pb for pb in armature.pose.bones
             if pb.bone.get("joint") == joint and pb.bone.get("bone") is not None]
    assert len(found) == 1, f"one bone hangs from joint {joint}"
    return found[0]


def depth(pose_bone):
    return 0 if pose_bone.parent is None else 1 + depth(pose_bone.parent)


posed_bones = sorted(((hanging_bone(r["joint"]), r) for r in rotations),
                     key=lambda pair: depth(pair[0]))
for pose_bone, rotation in posed_bones:
    bpy.context.view_layer.update()  # the parent's pose first
    parent = pose_bone.parent
    carried = (Matrix.Identity(4) if parent is None
               else parent.matrix @ parent.bone.matrix_local.inverted())
    pivot = Vector(skeleton["joints"][rotation["joint"]]["position"])
    axis = Vector(rotation["axis"]).normalized()
    turn = (Matrix.Translation(pivot) @ Matrix.Rotation(math.radians(rotation["degrees"]), 4, axis)
            @ Matrix.Translation(-pivot))
    pose_bone.matrix = carried @ world @ turn @ world.inverted() @ pose_bone.bone.matrix_local
bpy.context.view_layer.update()

evaluated = mesh.evaluated_get(bpy.context.evaluated_depsgraph_get())
words = open(posed_path).read().split()
count = int(words[1])
expected = [Vector([float(w) for w in words[4 + 3 * i:7 + 3 * i]]) for i in range(count)]
assert len(evaluated.data.vertices) == count, "Blender kept every vertex"
from_blender = to_blender.inverted() @ mesh.matrix_world  # mesh space -> primseg's coordinates
size = max(abs(x) for v in expected for x in v)
largest = max(((from_blender @ v.co) - e).length for v, e in zip(evaluated.data.vertices, expected))
print(f"Blender vs primseg deform: largest vertex difference {largest:.3g} (size {size:.3g})")
sys.exit(0 if largest <= 1e-5 * size else 1)
