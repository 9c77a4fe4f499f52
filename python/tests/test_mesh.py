"""read_mesh, Mesh(V, F) and the arrays they expose."""

import gc
import json

import numpy as np
import pytest

import primseg


def read_off_with_numpy(path):
    lines = [l for l in path.read_text().splitlines() if l.strip() and not l.startswith("#")]
    n, m = map(int, lines[1].split()[:2])
    V = np.array([l.split()[:3] for l in lines[2 : 2 + n]], dtype=np.float64)
    F = np.array([l.split()[1:4] for l in lines[2 + n : 2 + n + m]], dtype=np.int64)
    return V, F


def test_read_mesh_matches_the_file(fandisk):
    mesh = primseg.read_mesh(fandisk)
    V, F = read_off_with_numpy(fandisk)
    assert mesh.V.dtype == np.float64 and mesh.V.shape == V.shape
    assert mesh.F.dtype == np.int32 and mesh.F.shape == F.shape
    np.testing.assert_array_equal(mesh.V, V)
    np.testing.assert_array_equal(mesh.F, F)
    np.testing.assert_array_equal(mesh.face_of_triangle, np.arange(len(F)))
    assert (mesh.vertex_count, mesh.face_count, mesh.triangle_count) == (6475, 12946, 12946)


def test_read_mesh_accepts_str_and_pathlike(fandisk):
    np.testing.assert_array_equal(primseg.read_mesh(str(fandisk)).F, primseg.read_mesh(fandisk).F)


def test_polygons_are_split_and_traced_back(tmp_path):
    path = tmp_path / "quad_and_triangle.off"
    path.write_text("OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n4 0 1 2 3\n3 1 4 2\n")
    mesh = primseg.read_mesh(path)
    assert mesh.face_count == 2 and mesh.triangle_count == 3
    np.testing.assert_array_equal(mesh.face_of_triangle, [0, 0, 1])
    quad = [sorted(t) for t in mesh.F[:2].tolist()]
    assert all(set(t) <= {0, 1, 2, 3} and len(set(t)) == 3 for t in quad) and quad[0] != quad[1]
    np.testing.assert_array_equal(mesh.F[2], [1, 4, 2])
    labels = primseg.segment(mesh).cut(1)
    assert labels.shape == (2,)  # one label per input polygon, not per triangle


def test_arrays_are_read_only_views_that_keep_the_mesh_alive(fandisk):
    mesh = primseg.read_mesh(fandisk)
    V, F, owner = mesh.V, mesh.F, mesh.face_of_triangle
    assert V.ctypes.data == mesh.V.ctypes.data  # the same memory on every access: no copy
    assert F.ctypes.data == mesh.F.ctypes.data and owner.ctypes.data == mesh.face_of_triangle.ctypes.data
    for array in (V, F, owner):
        assert not array.flags.writeable
        with pytest.raises(ValueError):
            array[0] = 0
    expected = V.copy()
    del mesh
    gc.collect()
    np.testing.assert_array_equal(V, expected)  # the views own a reference to the mesh


def test_hierarchy_shares_the_mesh(fandisk):
    mesh = primseg.read_mesh(fandisk)
    h = primseg.segment(mesh, primitives="plane")
    assert h.mesh.V.ctypes.data == mesh.V.ctypes.data


@pytest.mark.parametrize("v_dtype", [np.float32, np.float64])
@pytest.mark.parametrize("f_dtype", [np.int32, np.int64, np.uint32, np.uint64])
@pytest.mark.parametrize("order", ["C", "F"])
def test_mesh_from_arrays_round_trips(fandisk, v_dtype, f_dtype, order):
    source = primseg.read_mesh(fandisk)
    V = np.asarray(source.V, dtype=v_dtype, order=order)
    F = np.asarray(source.F, dtype=f_dtype, order=order)
    mesh = primseg.Mesh(V, F)
    np.testing.assert_array_equal(mesh.V, V.astype(np.float64))
    np.testing.assert_array_equal(mesh.F, F)


def test_strided_and_byte_swapped_arrays_are_read_as_given():
    V = np.arange(36, dtype=np.float64).reshape(12, 3)
    F = np.array([[0, 1, 2], [9, 9, 9], [2, 1, 3], [9, 9, 9]], dtype=np.int64)
    mesh = primseg.Mesh(V[::3], F[::2])  # every third vertex, every other face
    np.testing.assert_array_equal(mesh.V, V[::3])
    np.testing.assert_array_equal(mesh.F, [[0, 1, 2], [2, 1, 3]])
    swapped = primseg.Mesh(V[::3].astype(">f8"), F[::2].astype(">i4"))
    np.testing.assert_array_equal(swapped.V, V[::3])
    np.testing.assert_array_equal(swapped.F, mesh.F)


def test_lists_are_accepted():
    mesh = primseg.Mesh([[0.0, 0, 0], [1.0, 0, 0], [0.0, 1, 0]], [[0, 1, 2]])
    assert mesh.face_count == 1


def test_reprs_count_in_words(fandisk):
    one = primseg.Mesh([[0.0, 0, 0], [1.0, 0, 0], [0.0, 1, 0]], [[0, 1, 2]])
    assert repr(one) == "<primseg.Mesh: 3 vertices, 1 face, 1 triangle>"
    assert repr(primseg.segment(one)) == "<primseg.Hierarchy: 1 face, 1 component>"
    mesh = primseg.read_mesh(fandisk)
    assert repr(mesh) == "<primseg.Mesh: 6475 vertices, 12946 faces, 12946 triangles>"


@pytest.mark.parametrize("extension, binary", [(".off", True), (".obj", True), (".ply", True),
                                               (".ply", False), (".stl", True), (".stl", False)])
def test_write_mesh_round_trips(fandisk, tmp_path, extension, binary):
    mesh = primseg.read_mesh(fandisk)
    path = tmp_path / f"copy{extension}"
    primseg.write_mesh(path, mesh, binary=binary)
    copy = primseg.read_mesh(path)
    if extension == ".stl":  # float32 triangle soup, welded again on reading
        assert copy.face_count == mesh.face_count
        np.testing.assert_allclose(np.sort(copy.V, axis=0), np.sort(mesh.V, axis=0), atol=1e-6)
    else:
        np.testing.assert_array_equal(copy.V, mesh.V)
        np.testing.assert_array_equal(copy.F, mesh.F)


def test_write_mesh_keeps_polygons_and_takes_new_positions(tmp_path):
    path = tmp_path / "quad_and_triangle.off"
    path.write_text("OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n4 0 1 2 3\n3 1 4 2\n")
    mesh = primseg.read_mesh(path)
    moved = mesh.V + [0, 0, 0.5]
    primseg.write_mesh(tmp_path / "moved.off", mesh, positions=moved.astype(np.float32))
    lines = (tmp_path / "moved.off").read_text().split("\n")
    assert lines[:2] == ["OFF", "5 2 0"] and lines[7:9] == ["4 0 1 2 3", "3 1 4 2"]
    np.testing.assert_array_equal(primseg.read_mesh(tmp_path / "moved.off").V, moved)
    np.testing.assert_array_equal(mesh.V[:, 2], 0)  # the Mesh itself is unchanged


def test_write_mesh_from_arrays_and_from_a_hierarchy(fandisk, tmp_path):
    mesh = primseg.read_mesh(fandisk)
    primseg.write_mesh(tmp_path / "arrays.ply", mesh.V, mesh.F)
    primseg.write_mesh(tmp_path / "tree.ply", primseg.segment(mesh))
    primseg.write_mesh(tmp_path / "mesh.ply", mesh)
    data = (tmp_path / "mesh.ply").read_bytes()
    assert (tmp_path / "arrays.ply").read_bytes() == data == (tmp_path / "tree.ply").read_bytes()


def test_write_mesh_rejects_bad_arguments(fandisk, tmp_path):
    mesh = primseg.read_mesh(fandisk)
    out = tmp_path / "out.ply"
    cases = [
        (dict(positions=mesh.V[:-1]), "positions has 6474 rows for 6475 vertices"),
        (dict(positions=np.where(np.arange(6475)[:, None] == 7, np.nan, mesh.V)),
         r"positions\[7, 0\] is nan"),
        (dict(positions=mesh.V.astype(np.int64)), "positions must be an array of float32 or float64"),
        (dict(labels=np.zeros(mesh.face_count, dtype=np.float64)), "labels must be an array of integers"),
        (dict(labels=np.zeros(3, dtype=np.int32)), r"one entry per face: shape \(12946,\)"),
        (dict(labels=np.full(mesh.face_count, -1)), r"labels\[0\] = -1 is not a cluster id"),
    ]
    for keywords, message in cases:
        with pytest.raises(ValueError, match=message):
            primseg.write_mesh(out, mesh, **keywords)
    with pytest.raises(ValueError, match="extension"):
        primseg.write_mesh(tmp_path / "out.xyz", mesh)
    with pytest.raises(OSError):
        primseg.write_mesh(tmp_path / "missing" / "out.ply", mesh)
    with pytest.raises(ValueError, match="F is missing"):
        primseg.write_mesh(out, mesh.V)
    with pytest.raises(ValueError, match=r"write_mesh\(mesh\) takes no F$"):
        primseg.write_mesh(out, mesh, mesh.F)
    with pytest.raises(ValueError, match=r"write_mesh\(hierarchy\) takes no F"):
        primseg.write_mesh(out, primseg.segment(mesh), mesh.F)
    assert not out.exists()


def test_info_counts_what_the_cli_prints(cli, tmp_path):
    from conftest import run_cli
    # Two components, a quad, an isolated vertex, a duplicate and a degenerate triangle.
    path = tmp_path / "defects.off"
    path.write_text("OFF\n9 4 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n5 0 0\n6 0 0\n5 1 0\n7 7 7\n7 0 0\n"
                    "4 0 1 2 3\n3 4 5 6\n3 6 5 4\n3 4 5 8\n")
    info = primseg.read_mesh(path).info()
    # Edge 4-5 has three triangles; the quad's four sides, 5-8 and 8-4 have one. The isolated
    # vertex (7, 7, 7) is outside the bounding box of the faces.
    assert info == {
        "vertices": 9, "isolated_vertices": 1, "faces": 4, "polygons": 1, "triangles": 5,
        "components": 2, "boundary_edges": 6, "non_manifold_edges": 1,
        "degenerate_triangles": 1, "duplicate_triangles": 1, "inconsistent_edges": 0,
        "inward_components": 0, "bbox_min": [0.0, 0.0, 0.0],
        "bbox_max": [7.0, 1.0, 0.0], "bbox_diagonal": 50 ** 0.5, "out_of_range": None}
    assert json.loads(run_cli(cli, "info", path, "--json", "-")) == info  # the same keys and values
    printed = [line.split() for line in run_cli(cli, "info", path).splitlines()[1:]]
    assert printed[:7] == [["vertices", "9", "(1", "isolated)"],
                           ["faces", "4", "(1", "polygons),", "5", "triangles"],
                           ["components", "2"], ["boundary", "edges", "6"],
                           ["non-manifold", "edges", "1"],
                           ["degenerate", "triangles", "1,", "duplicate", "triangles", "1"],
                           ["orientation", "consistent"]]
    # A tetrahedron listed inside out, then with one face turned back: as the CLI words it.
    tet = tmp_path / "tet.off"
    tet.write_text("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 3 1\n3 0 2 3\n3 1 3 2\n")
    assert primseg.read_mesh(tet).info()["inward_components"] == 1
    assert ["orientation", "consistent,", "1", "closed", "component", "facing", "inwards"] in [
        line.split() for line in run_cli(cli, "info", tet).splitlines()]
    tet.write_text("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 3 1\n3 0 2 3\n3 1 3 2\n")
    info = primseg.read_mesh(tet).info()
    assert (info["inconsistent_edges"], info["inward_components"]) == (3, 0)
    assert ["orientation", "inconsistent", "across", "3", "edges"] in [
        line.split() for line in run_cli(cli, "info", tet).splitlines()]
    far = primseg.Mesh(np.array([[0, 0, 0], [1e200, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    assert "vertex 1 has a coordinate of magnitude 1e+200" in far.info()["out_of_range"]
