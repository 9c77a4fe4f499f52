# %% [markdown]
# # Segmenting a CAD part into planes, cylinders and spheres
#
# A notebook-style script (Jupyter, VS Code and Spyder run each `# %%` cell; `python3
# segment_fandisk.py [MESH]` runs them all). It reads fandisk from Debian's libcgal-demo, builds
# primseg's hierarchy once, then looks at several levels of it with numpy and SciPy. The checks
# at the end of each cell make it a test too (CTest runs it).

# %%
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
