# %% [markdown]
# # Segmenting a CAD part into planes, cylinders and spheres
#
# A notebook-style script (Jupyter, VS Code and Spyder run each `# %%` cell; `python3
# segment_fandisk.py [MESH]` runs them all). It reads fandisk from Debian's libcgal-demo, builds
# primseg's hierarchy once, then looks at several levels of it with numpy and SciPy. The checks
# at the end of each cell make it a test too (CTest runs it).

# %%
import json
import pathlib
import sys
import tarfile
import tempfile
import time

import numpy as np

import primseg

if len(sys.argv) > 1:
    path = pathlib.Path(sys.argv[1])
else:  # fandisk from Debian's libcgal-demo, extracted to a temporary folder
    folder = pathlib.Path(tempfile.mkdtemp(prefix="primseg-example-"))
    with tarfile.open("/usr/share/doc/libcgal-dev/data.tar.gz") as archive:
        path = folder / "fandisk.off"
        path.write_bytes(archive.extractfile("data/meshes/fandisk.off").read())

mesh = primseg.read_mesh(path)
print(mesh)
print("V", mesh.V.shape, mesh.V.dtype, "  F", mesh.F.shape, mesh.F.dtype)
assert mesh.F.shape == (mesh.triangle_count, 3) and mesh.V.dtype == np.float64

# %% [markdown]
# ## The whole hierarchy, once
# `segment` accepts a Mesh or numpy arrays (V, F) as trimesh, Open3D or PyVista give them.

# %%
start = time.perf_counter()
tree = primseg.segment(mesh)
print(f"{tree} in {time.perf_counter() - start:.2f} s")

same_tree = primseg.segment(mesh.V, mesh.F.astype(np.int64))  # arrays: the same tree
assert np.array_equal(same_tree.linkage(), tree.linkage())

# %% [markdown]
# ## Any level, instantly
# By number of clusters, or by tolerance (absolute, or relative to the part's size).

# %%
labels = tree.cut(30)
print("30 clusters; faces per cluster:", np.bincount(labels)[:10], "...")
for name, level in [("0.1% of the diagonal (the CLI's default)", {}),
                    ("0.02% of the diagonal", {"relative_tolerance": 0.0002})]:
    print(f"{name}: {tree.cut(**level).max() + 1} clusters")
assert labels.shape == (mesh.face_count,) and labels.max() == 29

curve = tree.error_curve()  # (K, rms) for every K, to plot and pick a level by eye
print("RMS of the levels of 10, 30 and 100 clusters:", curve[[9, 29, 99], 1])
assert np.array_equal(curve[:, 0], np.arange(1, mesh.face_count + 1))

# %% [markdown]
# ## What each cluster is
# One dict per cluster, as in the CLI's JSON: fitted primitive, parameters, exact RMS and maximum
# distance of its vertices.

# %%
clusters = tree.clusters(30)
print(f"{'id':>3} {'type':9} {'faces':>6} {'area':>9} {'rms':>10}  parameters")
for c in clusters[:12]:
    params = ", ".join(f"{k}={np.round(v, 4).tolist()}" for k, v in c["params"].items())
    print(f"{c['id']:>3} {c['type']:9} {c['faces']:>6} {c['area']:9.5f} {c['rms']:10.3g}  {params}")

cylinders = [c for c in clusters if c["type"] == "cylinder"]
print("cylinder radii:", sorted(round(c["params"]["radius"], 4) for c in cylinders))
assert sum(c["faces"] for c in clusters) == mesh.face_count
assert clusters[0]["type"] == "plane" and cylinders  # fandisk: flat faces and fillets
assert all(c["rms"] <= c["max"] for c in clusters)

# %% [markdown]
# ## Where the clusters meet
# The borders, as in the CLI's JSON: each pair of clusters that share edges, the curves of
# vertices along which they meet, and the angle between their fitted surfaces there. A fillet
# meets its faces tangentially (near 0 degrees); a sharp edge shows its dihedral turn (90 on a box).

# %%
borders = tree.borders(30)
angles = np.array([b["angle"] for b in borders])
print(f"{len(borders)} borders: {np.sum(angles < 7)} tangent (< 7 degrees),"
      f" {np.sum(angles > 80)} sharp (> 80 degrees)")
sharpest = max(borders, key=lambda b: b["length"] if b["angle"] > 80 else 0)
first, second = sharpest["clusters"]
print(f"the longest sharp edge: clusters {first} ({clusters[first]['type']}) and {second}"
      f" ({clusters[second]['type']}),"
      f" {sharpest['length']:.3f} long, {sharpest['angle']:.1f} degrees")
assert all(border["clusters"][1] is not None for border in borders)  # fandisk is closed
assert np.sum(angles < 7) >= 5 and np.sum(angles > 80) >= 5

# %% [markdown]
# ## The design intent
# Which fits are parallel, coaxial, at right angles, of one radius or tangent (a cylinder and a face
# or a cylinder of its direction it borders) within their uncertainty; with
# `regularize=True` the clusters' primitives have these relations made exact (the CLI's
# `--regularize`), as a CAD model would have them.

# %%
relations = tree.relations(30)
for kind in ("parallel", "coaxial", "orthogonal", "equal_radius", "tangent"):
    print(f"{kind}: {sum(r['kind'] == kind for r in relations)}")
exact = tree.clusters(30, regularize=True)
# The cylinders of a coaxial set (which may also hold spheres centred on their axis).
coaxial = next(cylinders for r in relations if r["kind"] == "coaxial"
               for cylinders in [[c for c in r["clusters"] if exact[c]["type"] == "cylinder"]] if cylinders)
radii = [exact[c]["params"]["radius"] for c in coaxial]
print("one axis for the cylinders", coaxial, "of radii", np.round(radii, 4))
axes = np.array([exact[c]["params"]["axis"] for c in coaxial])
assert np.all(np.abs(axes) == np.abs(axes[0]))  # one direction, bit for bit
right_angle = next(r for r in relations if r["kind"] == "orthogonal")


def direction(c):
    return np.array(exact[c]["params"].get("normal", exact[c]["params"].get("axis")))


assert abs(direction(right_angle["clusters"][0]) @ direction(right_angle["orthogonal_to"][0])) < 1e-14
for same in (r["clusters"] for r in relations if r["kind"] == "equal_radius"):
    radii = {exact[c]["params"]["radius"] for c in same}
    print("one radius for the clusters", same, ":", radii)
    assert len(radii) == 1


def check_tangent(pairs, fits):
    """A tangent cylinder's axis lies along its plane, at its radius from it; two tangent
    cylinders share their direction, their axes the sum or the difference of their radii apart."""
    def direction_of(c):
        return np.array(fits[c]["params"].get("normal", fits[c]["params"].get("axis")))

    for pair in pairs:
        cylinder, other = sorted(pair, key=lambda c: fits[c]["type"] != "cylinder")
        point = np.array(fits[cylinder]["params"]["point"])
        radius = fits[cylinder]["params"]["radius"]
        if fits[other]["type"] == "cylinder":
            axis = np.array(fits[other]["params"]["axis"])
            offset = point - fits[other]["params"]["point"]
            apart = np.linalg.norm(offset - (offset @ axis) * axis)
            others = fits[other]["params"]["radius"]
            print(f"cylinders {cylinder} and {other} of radii {radius:.4f} and {others:.4f} tangent:"
                  f" their axes {apart:.4f} apart")
            assert np.all(np.abs(direction_of(cylinder)) == np.abs(axis))
            assert min(abs(apart - (radius + others)), abs(apart - abs(radius - others))) < 1e-12
            continue
        normal = direction_of(other)
        gap = abs(normal @ (point - fits[other]["params"]["point"]))
        print(f"cylinder {cylinder} of radius {radius:.4f} tangent to plane {other}: its axis"
              f" {gap:.4f} from it")
        assert abs(normal @ direction_of(cylinder)) < 1e-14
        assert abs(gap - radius) < 1e-12


tangent = [r["clusters"] for r in relations if r["kind"] == "tangent"]
assert tangent
check_tangent(tangent, exact)

# %% [markdown]
# ## A CAD part's tolerances
# fandisk is an exact tessellation: its fits are known so precisely that the export's own small
# errors are many standard deviations, and some relations the part was drawn with are refused. A
# reverse engineer who knows the part's tolerances gives them (degrees, input units): relations
# within them hold whatever the statistics say.

# %%
tolerances = dict(relation_angle_tolerance=0.05, relation_length_tolerance=2e-5)
tolerant = tree.relations(30, **tolerances)
tangent_within = [r["clusters"] for r in tolerant if r["kind"] == "tangent"]
print(f"tangent pairs: {len(tangent)} by the statistics, {len(tangent_within)} within the"
      f" tolerances: {tangent_within}")
assert len(tangent_within) > len(tangent)
# At the automatic level (34 clusters) a fillet rounds the edge between a face and a large
# cylinder of its direction: within the tolerances it is tangent to both, as drawn.
automatic = [r["clusters"] for r in tree.relations("auto", **tolerances) if r["kind"] == "tangent"]
automatic_fits = tree.clusters("auto", regularize=True, **tolerances)
fillet_between = [pair for pair in automatic
                  if all(automatic_fits[c]["type"] == "cylinder" for c in pair)]
assert fillet_between
fillet = next(c for c in fillet_between[0] if automatic_fits[c]["params"]["radius"] < 1)
assert any(fillet in pair and any(automatic_fits[c]["type"] == "plane" for c in pair)
           for pair in automatic)
check_tangent(automatic, automatic_fits)

# %% [markdown]
# ## The design intent of many levels at once
# `relations_of_levels` gives the regularized clusters and the relations of many levels in one
# call, as `clusters(k, regularize=True)` and `relations(k)` give them level by level, but
# gathering each cluster's vertices once: to see at which level a relation appears or goes.

# %%
start = time.perf_counter()
levels = tree.relations_of_levels(range(10, 61, 5))
print(f"{len(levels)} levels in {time.perf_counter() - start:.2f} s")
kinds = ("parallel", "coaxial", "orthogonal", "equal_radius", "coplanar", "tangent")
print("  k " + " ".join(f"{kind:>12}" for kind in kinds))
for level in levels:
    found = [r["kind"] for r in level["relations"]]
    print(f"{level['k']:>3} " + " ".join(f"{found.count(kind):>12}" for kind in kinds))
at_30 = next(level for level in levels if level["k"] == 30)
assert at_30["relations"] == relations and at_30["clusters"] == exact
assert all(any(r["kind"] == "coaxial" for r in level["relations"]) for level in levels[2:])

# %% [markdown]
# ## Per-face quantities with numpy
# Labels index the cluster list, so per-face arrays are one fancy-indexing away: here the RMS
# distance of each face's cluster, ready to colour a mesh viewer with.

# %%
rms_per_face = np.array([c["rms"] for c in clusters])[labels]
worst = int(np.argmax(rms_per_face))
print(f"face {worst} lies in the worst-fitting cluster: rms {rms_per_face[worst]:.3g}")
assert rms_per_face.shape == (mesh.face_count,)

# %% [markdown]
# ## The tree in SciPy
# `linkage()` is a SciPy linkage matrix: dendrograms, cut_tree, fcluster all apply.

# %%
try:
    from scipy.cluster import hierarchy
except ImportError:
    hierarchy = None
    print("SciPy not installed (apt-get install python3-scipy): skipping this cell")
if hierarchy is not None:
    Z = tree.linkage()
    top = hierarchy.dendrogram(Z, truncate_mode="lastp", p=8, no_plot=True)
    print("sizes of the 8 top branches:", top["ivl"])
    scipy_labels = hierarchy.fcluster(Z, 30, criterion="maxclust")
    pairs = np.unique(np.stack([scipy_labels, labels]), axis=1)
    assert pairs.shape[1] == 30  # the same 30 clusters, numbered differently
    print("scipy's fcluster(Z, 30, 'maxclust') gives the same 30 clusters")

# %% [markdown]
# ## Keep the tree
# The tree file holds the mesh and the whole hierarchy: reload it (or `primseg cut` it) later.

# %%
tree_path = pathlib.Path(tempfile.mkdtemp(prefix="primseg-example-")) / "fandisk.tree"
tree.save(tree_path)
reloaded = primseg.read_tree(tree_path)
assert np.array_equal(reloaded.cut(30), labels)
print(f"saved and reloaded {tree_path.name}: {tree_path.stat().st_size / 1e6:.1f} MB")

# %% [markdown]
# ## Denoising: snap the vertices onto the primitives
# Noise of 0.1% of the diagonal blurs fandisk's sharp edges. `denoise` segments the noisy mesh,
# then moves every vertex onto its cluster's primitive (a vertex between clusters onto their
# intersection, which restores the edges); `distance` measures the result against the clean part
# as `primseg distance --json` does. The RMS distance drops by about half; the largest distance
# can grow, where a vertex near a border snapped onto its neighbour's primitive.

# %%
rng = np.random.default_rng(1)
noisy_V = mesh.V + rng.normal(scale=1e-3 * mesh.bounding_box_diagonal, size=mesh.V.shape)
start = time.perf_counter()
clean_V, rounds, level = primseg.denoise(noisy_V, mesh.F, k=30, return_rounds=True,
                                         return_level=True)
print(f"denoised in {time.perf_counter() - start:.2f} s:", rounds[0])
# The clusters the vertices went onto meet along the denoised mesh's feature lines: the sharp
# ones are fandisk's recovered edges.
sharp = [b for b in level["borders"] if b["angle"] is not None and b["angle"] > 60]
print(f"{len(level['clusters'])} clusters; {len(sharp)} sharp borders, "
      f"{sum(b['length'] for b in sharp):.3f} long in all")
assert len(level["clusters"]) == rounds[0]["clusters"] and len(sharp) > 20
before = primseg.distance(mesh, (noisy_V, mesh.F), samples=50000)
after = primseg.distance(mesh, (clean_V, mesh.F), samples=50000)
for name, d in [("noisy", before), ("denoised", after)]:
    s = d["symmetric"]
    print(f"{name:9} to the original: rms {s['rms_percent']:.4f}%  hausdorff {s['max_percent']:.4f}%"
          " of the diagonal")
assert clean_V.shape == mesh.V.shape and clean_V.dtype == np.float64
assert after["symmetric"]["rms"] < 0.6 * before["symmetric"]["rms"]

# Saved with the mesh's faces, as `primseg denoise -o` saves it; and the 30 clusters as colours.
folder = tree_path.parent
primseg.write_mesh(folder / "fandisk-denoised.ply", mesh, positions=clean_V)
primseg.write_mesh(folder / "fandisk-clusters.ply", mesh, labels=labels)
assert np.array_equal(primseg.read_mesh(folder / "fandisk-denoised.ply").V, clean_V)
print("wrote", ", ".join(p.name for p in sorted(folder.glob("*.ply"))))

# %% [markdown]
# ## A skeleton, and a pose
# On a natural shape, cylinders only, the clusters are limbs and the skeleton follows: one bone
# per cluster, one joint where clusters meet (here man.off from the same archive). `deform`
# rotates joints and moves the vertices by linear blend skinning.

# %%
if len(sys.argv) <= 2:
    man_path = path.parent / "man.off"
    with tarfile.open("/usr/share/doc/libcgal-dev/data.tar.gz") as archive:
        man_path.write_bytes(archive.extractfile("data/meshes/man.off").read())
else:
    man_path = pathlib.Path(sys.argv[2])
man = primseg.read_mesh(man_path)
skeleton = primseg.skeleton(man, k=20)  # primitives=("cylinder",) by default, as the CLI
kinds = [j["kind"] for j in skeleton.joints]
print(skeleton, {kind: kinds.count(kind) for kind in sorted(set(kinds))})
weights = skeleton.skin_weights()  # (n, K): one weight per bone per vertex, rows summing to 1
joint = next(j["id"] for j in skeleton.joints
             if j["kind"] == "sensitive" and len(skeleton.bones_beyond(j["id"])) < 5)
posed = skeleton.deform([{"joint": joint, "axis": [1, 0, 0], "degrees": 45}])
moved = np.linalg.norm(posed - man.V, axis=1) > 0
print(f"rotating joint {joint} by 45 degrees moves {moved.sum()} of {len(man.V)} vertices"
      f" (bones {skeleton.bones_beyond(joint)})")
assert np.allclose(weights[np.unique(man.F)].sum(axis=1), 1.0)
assert 0 < moved.sum() < len(man.V)

# The rig for other tools: the mesh skinned to this skeleton as binary glTF (Blender, three.js,
# game engines). Rotating the node of the bone that hangs from `joint` by the same 45 degrees
# poses the mesh as `deform` did.
rig = skeleton.gltf()
(folder / "man-rig.glb").write_bytes(rig)
hanging = [n["name"] for n in json.loads(rig[20:20 + int.from_bytes(rig[12:16], "little")])["nodes"]
           if n.get("extras", {}).get("joint") == joint and "bone" in n["extras"]]
print(f"wrote man-rig.glb ({len(rig) / 1e6:.1f} MB); joint {joint} turns node {hanging[0]}")
assert rig[:4] == b"glTF" and len(hanging) == 1
