"""segment, cut, clusters, save/read_tree: the same results as the CLI, from any array layout."""

import copy as copy_module
import json
import multiprocessing
import os
import pickle
import signal
import threading
import time
import tracemalloc

import numpy as np
import pytest

import primseg
from conftest import assert_releases_the_gil, capped_cylinder, run_cli, same_partition


@pytest.fixture(scope="module")
def fandisk_tree(fandisk):
    return primseg.segment(primseg.read_mesh(fandisk))


@pytest.mark.parametrize(
    "cli_level, python_level",
    [((), {}), (("--clusters", "30"), {"k": 30}), (("--clusters", "1"), {"k": 1}),
     (("--clusters", "auto"), {"k": "auto"}),
     (("--tolerance", "0.05%"), {"relative_tolerance": 0.0005}),
     (("--tolerance", "0.002"), {"tolerance": 0.002}),
     (("--clusters", "30", "--refine", "5"), {"k": 30, "refine": 5}),
     (("--tolerance", "0.05%", "--refine", "2"), {"relative_tolerance": 0.0005, "refine": 2})])
def test_labels_and_clusters_match_the_cli(cli, fandisk, fandisk_tree, tmp_path, cli_level, python_level):
    run_cli(cli, "segment", fandisk, *cli_level, "--labels", tmp_path / "l.txt",
            "--json", tmp_path / "c.json", "--quiet")
    expected = np.loadtxt(tmp_path / "l.txt", dtype=np.int64)
    labels = fandisk_tree.cut(**python_level)
    assert labels.dtype == np.int32 and labels.shape == (12946,)
    np.testing.assert_array_equal(labels, expected)
    # Same keys, same numbers, bit for bit (JSON doubles round-trip).
    assert fandisk_tree.clusters(**python_level) == json.loads((tmp_path / "c.json").read_text())["clusters"]


@pytest.mark.parametrize("cli_level, python_level",
                         [(("--clusters", "30"), {"k": 30}),
                          (("--clusters", "20", "--refine", "3"), {"k": 20, "refine": 3})])
def test_borders_match_the_cli(cli, fandisk, fandisk_tree, tmp_path, cli_level, python_level):
    run_cli(cli, "segment", fandisk, *cli_level, "--json", tmp_path / "c.json", "--quiet")
    borders = fandisk_tree.borders(**python_level)
    assert json.loads(json.dumps(borders)) == json.loads((tmp_path / "c.json").read_text())["borders"]


def test_regularized_level_matches_the_cli(cli, fandisk, fandisk_tree, tmp_path):
    run_cli(cli, "segment", fandisk, "--clusters", "30", "--refine", "2", "--regularize",
            "--json", tmp_path / "c.json", "--quiet")
    expected = json.loads((tmp_path / "c.json").read_text())
    relations = fandisk_tree.relations(30, refine=2)
    assert relations == expected["relations"]
    clusters = fandisk_tree.clusters(30, refine=2, regularize=True)
    assert clusters == expected["clusters"]
    borders = fandisk_tree.borders(30, refine=2, regularize=True)
    assert json.loads(json.dumps(borders)) == expected["borders"]
    # The relations are exact: one direction per parallel group (and per side of a right angle),
    # one axis line per coaxial set, right angles to round-off, one radius per equal-radius set,
    # a tangent cylinder's axis at its radius from its plane.
    kinds = {r["kind"] for r in relations}
    assert kinds == {"parallel", "coaxial", "orthogonal", "equal_radius", "tangent"}

    def direction(c):
        params = clusters[c]["params"]
        return np.array(params.get("normal", params.get("axis")))

    for relation in relations:
        if relation["kind"] == "equal_radius":
            assert len({clusters[c]["params"]["radius"] for c in relation["clusters"]}) == 1
            continue
        if relation["kind"] == "tangent":
            types = {clusters[c]["type"]: clusters[c]["params"] for c in relation["clusters"]}
            cylinder, plane = types["cylinder"], types["plane"]
            normal, axis = np.array(plane["normal"]), np.array(cylinder["axis"])
            assert abs(normal @ axis) < 1e-14
            gap = abs(normal @ (np.array(cylinder["point"]) - np.array(plane["point"])))
            assert abs(gap - cylinder["radius"]) < 1e-12 * cylinder["radius"]
            continue
        sides = [relation["clusters"]] + ([relation["orthogonal_to"]] if "orthogonal_to" in relation else [])
        for side in sides:
            # A coaxial set's spheres have no direction, only a centre on its axis line.
            directions = [direction(c) for c in side if clusters[c]["type"] != "sphere"]
            for d in directions:
                assert np.array_equal(d, directions[0]) or np.array_equal(d, -directions[0])
        if relation["kind"] == "orthogonal":
            assert abs(direction(sides[0][0]) @ direction(sides[1][0])) < 1e-14
        if relation["kind"] == "coaxial":
            # On one line: its cylinders' axis, or without a cylinder the one through the centres.
            params = [clusters[c]["params"] for c in relation["clusters"]]
            points = np.array([p.get("point", p.get("center")) for p in params])
            line = next((p for p in params if "axis" in p), None)
            if line is None:
                assert len(params) >= 3
                line = {"point": points[0], "axis": (points[-1] - points[0]) / np.linalg.norm(points[-1] - points[0])}
            axis, point = np.array(line["axis"]), np.array(line["point"])
            for p in points:
                assert np.linalg.norm(np.cross(p - point, axis)) < 1e-12
    # Without regularize, the fits are the level's own.
    assert fandisk_tree.clusters(30, refine=2) != clusters


def test_coplanar_faces_of_a_part_share_one_plane(cgal_mesh):
    # couplingdown's faces cut apart by its holes: at its automatic level each coplanar set is one
    # plane (one normal up to its side, every member's point on it), and a plane's members are
    # also members of one parallel relation.
    tree = primseg.segment(primseg.read_mesh(str(cgal_mesh("couplingdown.off"))))
    relations = tree.relations("auto", refine=2)
    clusters = tree.clusters("auto", refine=2, regularize=True)
    coplanar = [r["clusters"] for r in relations if r["kind"] == "coplanar"]
    assert len(coplanar) == 2 and sorted(len(s) for s in coplanar) == [3, 4]
    parallel = [set(r["clusters"]) for r in relations if r["kind"] == "parallel"]
    for members in coplanar:
        assert any(set(members) <= group for group in parallel)
        normal = np.array(clusters[members[0]]["params"]["normal"])
        point = np.array(clusters[members[0]]["params"]["point"])
        for c in members:
            assert clusters[c]["type"] == "plane"
            assert abs(abs(np.array(clusters[c]["params"]["normal"]) @ normal) - 1) < 1e-15
            assert abs((np.array(clusters[c]["params"]["point"]) - point) @ normal) < 1e-14


TIGHT_RELATIONS = dict(relation_significance=2.5, max_relation_angle=10.0, max_radius_difference=0.001)
# A CAD part's tolerances: fandisk's exact tessellation errs by more than its fits' statistics.
CAD_TOLERANCES = dict(relation_angle_tolerance=0.05, relation_length_tolerance=2e-5)
# The same as a percentage of the bounding-box diagonal, as the CLI spells it.
CAD_TOLERANCES_IN_PERCENT = dict(relation_angle_tolerance=0.05, relation_length_tolerance="0.0014%")


def cli_options(keywords):
    return [text for name, value in keywords.items()
            for text in ("--" + name.replace("_", "-"),
                         value if isinstance(value, str) else repr(value))]


@pytest.mark.parametrize("keywords", [TIGHT_RELATIONS, CAD_TOLERANCES, CAD_TOLERANCES_IN_PERCENT],
                         ids=["tight", "cad", "cad-percent"])
def test_relation_options_are_the_clis(cli, fandisk, fandisk_tree, tmp_path, keywords):
    # The options of --regularize, as keywords: the same relations and fits as the CLI's, other
    # relations than the defaults (fewer equal radii with a tighter radius bound, more with
    # tolerances), and out-of-range values refused.
    run_cli(cli, "segment", fandisk, "--clusters", "60", "--regularize", *cli_options(keywords),
            "--json", tmp_path / "c.json", "--quiet")
    expected = json.loads((tmp_path / "c.json").read_text())
    relations = fandisk_tree.relations(60, **keywords)
    assert relations == expected["relations"]
    assert fandisk_tree.clusters(60, regularize=True, **keywords) == expected["clusters"]
    borders = fandisk_tree.borders(60, regularize=True, **keywords)
    assert json.loads(json.dumps(borders)) == expected["borders"]
    assert relations != fandisk_tree.relations(60)
    for bad in (dict(relation_significance=0.0), dict(max_relation_angle=90.0),
                dict(relation_angle_tolerance=-1.0), dict(relation_angle_tolerance=20.0),
                dict(relation_length_tolerance=-1e-9), dict(relation_length_tolerance=float("inf")),
                dict(relation_length_tolerance="0.01"), dict(relation_length_tolerance="-1%"),
                dict(relation_length_tolerance="inf%"), dict(relation_length_tolerance="%"),
                dict(relation_length_tolerance="1e-3 %"), dict(max_radius_difference=1.0)):
        (keyword,) = bad
        with pytest.raises(ValueError, match=keyword):  # named as the caller spells it
            fandisk_tree.relations(60, **bad)


def test_a_relation_length_tolerance_in_percent_is_of_the_diagonal(fandisk_tree):
    # "L%" is L percent of the bounding-box diagonal, the same double the CLI computes. Fandisk's
    # fillet 7 is tangent to its face 4 at 0.0014% (its own fit is 0.0012% of the diagonal from
    # tangent; refitted tangent, its RMS rises by about 0.00075%), and not at 0.0005%.
    diagonal = fandisk_tree.mesh.bounding_box_diagonal
    in_percent = fandisk_tree.relations("auto", refine=2, relation_length_tolerance="0.0014%")
    assert in_percent == fandisk_tree.relations("auto", refine=2,
                                                relation_length_tolerance=0.0014 / 100 * diagonal)
    tangent = {"kind": "tangent", "clusters": [4, 7]}
    assert any(r.items() >= tangent.items() for r in in_percent)
    closer = fandisk_tree.relations("auto", refine=2, relation_length_tolerance="0.0005%")
    assert not any(r.items() >= tangent.items() for r in closer)


def assert_levels_are_the_one_level_calls(tree, levels, ks, **keywords):
    """relations_of_levels(ks, **keywords) against clusters(k, regularize=True) and relations(k)
    for each k: equal, and bit for bit (repr tells -0.0 from 0.0)."""
    assert [level["k"] for level in levels] == list(ks)
    for level in levels:
        expected = {"k": level["k"],
                    "clusters": tree.clusters(level["k"], regularize=True, **keywords),
                    "relations": tree.relations(level["k"], **keywords)}
        assert level == expected
        assert repr(level) == repr(expected)


def test_relations_of_levels_are_the_one_level_calls(fandisk_tree):
    # Levels in any order, repeated, below and above each other: each is what the one-level calls
    # give, on any thread count.
    ks = [60, 1, 30, 2, 30, 100, 7]
    levels = fandisk_tree.relations_of_levels(ks)
    assert_levels_are_the_one_level_calls(fandisk_tree, levels, ks)
    assert levels[2] == levels[4] and levels[2] is not levels[4]  # a repeat: its own dicts
    for threads in (1, 3):
        assert fandisk_tree.relations_of_levels(ks, threads=threads) == levels
    # Not vacuous: the levels have relations of several kinds, and fits they changed.
    assert {r["kind"] for r in levels[0]["relations"]} >= {"parallel", "orthogonal", "coaxial"}
    assert levels[0]["clusters"] != fandisk_tree.clusters(60)
    # The relation options, as relations() and clusters() spell them.
    for keywords in (TIGHT_RELATIONS, CAD_TOLERANCES, CAD_TOLERANCES_IN_PERCENT):
        other = fandisk_tree.relations_of_levels([60, 30], **keywords)
        assert_levels_are_the_one_level_calls(fandisk_tree, other, [60, 30], **keywords)
        assert other[0]["relations"] != levels[0]["relations"]
    # Any sequence of integers: a range, a numpy array; none gives none.
    assert fandisk_tree.relations_of_levels(range(5, 8)) == fandisk_tree.relations_of_levels(
        np.array([5, 6, 7], dtype=np.int32))
    assert fandisk_tree.relations_of_levels([]) == []


def test_relations_of_levels_find_the_coplanar_faces_of_each_level(cgal_mesh):
    # couplingdown's faces cut apart by its holes, level by level from 1 to 60 clusters: the
    # coplanar sets (and every other relation and fit) of each level as relations(k) finds them.
    tree = primseg.segment(primseg.read_mesh(str(cgal_mesh("couplingdown.off"))))
    ks = range(1, 61)
    levels = tree.relations_of_levels(ks)
    assert_levels_are_the_one_level_calls(tree, levels, ks)
    coplanar = [[r for r in level["relations"] if r["kind"] == "coplanar"] for level in levels]
    assert sum(map(bool, coplanar)) >= 40 and max(map(len, coplanar)) >= 2


def test_relations_of_levels_releases_the_gil(fandisk_tree):
    assert_releases_the_gil(lambda: fandisk_tree.relations_of_levels(range(1, 101), threads=1))


def test_borders_of_a_capped_cylinder_are_two_circles_at_right_angles():
    V, F, regions = capped_cylinder()
    tree = primseg.segment(V, F)
    assert same_partition(tree.cut(3), regions)
    borders = tree.borders(3)
    assert [b["clusters"][1] is None for b in borders] == [False, False]
    for border in borders:
        assert border["angle"] == pytest.approx(90, abs=1e-6)
        [curve] = border["curves"]
        assert curve["closed"] and len(curve["vertices"]) == 48
        assert border["edges"] == 48


def test_refinement_moves_border_faces_and_checks_its_pass_count(fandisk_tree):
    cut = fandisk_tree.cut(30)
    refined = fandisk_tree.cut(30, refine=5)
    assert 0 < np.count_nonzero(refined != cut) < cut.size // 10
    np.testing.assert_array_equal(fandisk_tree.cut(30, refine=0), cut)
    for passes in (-1, 1001):
        with pytest.raises(ValueError, match="refine"):
            fandisk_tree.cut(30, refine=passes)
        with pytest.raises(ValueError, match="refine"):
            fandisk_tree.clusters(30, refine=passes)


def test_linkage_matches_the_cli(cli, fandisk, fandisk_tree, tmp_path):
    run_cli(cli, "segment", fandisk, "--linkage", tmp_path / "z.txt", "--quiet")
    np.testing.assert_array_equal(fandisk_tree.linkage(), np.loadtxt(tmp_path / "z.txt"))


def test_tree_file_round_trip_with_the_cli(cli, fandisk_tree, tmp_path):
    fandisk_tree.save(tmp_path / "f.tree")
    reread = primseg.read_tree(tmp_path / "f.tree")
    np.testing.assert_array_equal(reread.linkage(), fandisk_tree.linkage())
    np.testing.assert_array_equal(reread.mesh.V, fandisk_tree.mesh.V)
    run_cli(cli, "cut", tmp_path / "f.tree", "--clusters", "12", "--labels", tmp_path / "l.txt", "--quiet")
    np.testing.assert_array_equal(reread.cut(12), np.loadtxt(tmp_path / "l.txt"))


def _segment_in_a_worker(path):
    return primseg.segment(primseg.read_mesh(path))


def test_pickled_trees_and_meshes_come_back_the_same(fandisk, fandisk_tree):
    # Across processes (multiprocessing, joblib pickle what they send): a tree built in a worker.
    context = multiprocessing.get_context("spawn")
    with context.Pool(1) as pool:
        from_worker = pool.apply(_segment_in_a_worker, (str(fandisk),))
    state = pickle.dumps(fandisk_tree)
    for copy in (from_worker, pickle.loads(state)):
        assert pickle.dumps(copy) == state  # the tree file's bytes: the same tree, bit for bit
        np.testing.assert_array_equal(copy.linkage(), fandisk_tree.linkage())
        np.testing.assert_array_equal(copy.cut(30, refine=2), fandisk_tree.cut(30, refine=2))
    mesh = pickle.loads(pickle.dumps(fandisk_tree.mesh))
    for name in ("V", "F", "face_of_triangle"):
        np.testing.assert_array_equal(getattr(mesh, name), getattr(fandisk_tree.mesh, name))
    assert mesh.face_count == fandisk_tree.mesh.face_count
    # Read-only objects: a copy is the object itself.
    assert copy_module.deepcopy(fandisk_tree) is fandisk_tree
    original = fandisk_tree.mesh
    assert copy_module.copy(original) is original


def test_corrupt_pickles_are_refused(fandisk_tree):
    tree_state = fandisk_tree.__getstate__()
    bad_tree = tree_state[0][:100] + bytes([tree_state[0][100] ^ 1]) + tree_state[0][101:]
    with pytest.raises(primseg.ParseError, match="pickled primseg.Hierarchy: checksum"):
        primseg.Hierarchy.__new__(primseg.Hierarchy).__setstate__((bad_tree,))
    with pytest.raises(primseg.InvalidInputError, match="not a pickled primseg.Hierarchy"):
        primseg.Hierarchy.__new__(primseg.Hierarchy).__setstate__(("text",))
    V, offsets, polygons, triangles, faces = fandisk_tree.mesh.__getstate__()
    cases = [
        ((V[:-1], offsets, polygons, triangles, faces), "positions has .* bytes"),
        ((V, offsets, polygons, triangles[:-12], faces), "triangles but"),
        ((V, offsets, polygons, triangles, faces[:-4] + b"\xff\xff\xff\x7f"), "face_of_triangle"),
        ((V[: 24 * 10], offsets, polygons, triangles, faces), "vertex|vertices"),
        ((V, offsets, polygons), "not a pickled primseg.Mesh"),
    ]
    for state, message in cases:
        with pytest.raises(primseg.InvalidInputError, match=message):
            primseg.Mesh.__new__(primseg.Mesh).__setstate__(state)


@pytest.mark.parametrize("f_dtype", [np.int32, np.int64, np.uint32, np.uint64])
@pytest.mark.parametrize("order", ["C", "F"])
def test_arrays_give_the_tree_of_the_file(fandisk, fandisk_tree, f_dtype, order):
    mesh = fandisk_tree.mesh
    V = np.asarray(mesh.V, order=order)
    F = np.asarray(mesh.F, dtype=f_dtype, order=order)
    h = primseg.segment(V, F)
    np.testing.assert_array_equal(h.linkage(), fandisk_tree.linkage())
    np.testing.assert_array_equal(h.cut(), fandisk_tree.cut())


def test_float32_vertices_are_their_float64_values(fandisk_tree):
    V32 = fandisk_tree.mesh.V.astype(np.float32)
    F = fandisk_tree.mesh.F
    np.testing.assert_array_equal(primseg.segment(V32, F).linkage(),
                                  primseg.segment(V32.astype(np.float64), F).linkage())


def test_no_converted_copy_of_the_input(fandisk_tree):
    # numpy reports its buffers to tracemalloc: a float32 -> float64 or Fortran -> C conversion
    # would allocate at least V.nbytes * 2 traced bytes.
    V = np.asfortranarray(fandisk_tree.mesh.V.astype(np.float32))
    F = np.asfortranarray(fandisk_tree.mesh.F.astype(np.int64))
    tracemalloc.start()
    try:
        primseg.Mesh(V, F)
        primseg.segment(V, F, primitives="plane")
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < V.nbytes / 4, peak


def test_labels_own_their_memory(fandisk_tree):
    labels = fandisk_tree.cut(5)
    assert labels.flags.writeable and labels.flags.c_contiguous
    labels[:] = 0  # the caller's array: editing it changes nothing else
    assert fandisk_tree.cut(5).max() == 4


def test_ground_truth_cylinder_and_planes():
    V, F, regions = capped_cylinder(radius=2.0, height=5.0, center=(1.0, -2.0, 0.5))
    h = primseg.segment(V, F)
    labels = h.cut(3)
    clusters = h.clusters(3)
    for label, cluster in enumerate(clusters):
        assert len(np.unique(regions[labels == label])) == 1  # each cluster is one true region
        assert cluster["faces"] == np.count_nonzero(labels == label)
    by_type = sorted(c["type"] for c in clusters)
    assert by_type == ["cylinder", "plane", "plane"]
    cylinder = next(c for c in clusters if c["type"] == "cylinder")
    assert abs(cylinder["params"]["radius"] - 2.0) < 1e-6
    assert np.allclose(np.abs(cylinder["params"]["axis"]), [0, 0, 1], atol=1e-9)
    assert np.allclose(cylinder["params"]["point"][:2], [1.0, -2.0], atol=1e-6)
    assert cylinder["rms"] < 1e-6 and cylinder["max"] < 1e-6
    for plane in (c for c in clusters if c["type"] == "plane"):
        assert np.allclose(np.abs(plane["params"]["normal"]), [0, 0, 1], atol=1e-9)
        assert min(abs(plane["params"]["point"][2] - z) for z in (0.5, 5.5)) < 1e-9
    json.dumps(clusters)  # plain Python values


def test_merges_hold_every_nodes_own_fit():
    V, F, regions = capped_cylinder(radius=2.0, height=5.0, center=(1.0, -2.0, 0.5))
    h = primseg.segment(V, F)
    merges = h.merges()
    F_count = h.face_count
    assert all(len(column) == F_count - 1 for column in merges.values())
    Z = h.linkage()
    np.testing.assert_array_equal(merges["children"], Z[:, :2])
    np.testing.assert_array_equal(merges["face_count"], Z[:, 3])
    assert not merges["trailing"].any() and (merges["type"] != "").all()
    # The node of each of the three clusters: a face's ancestor with the cluster's face count.
    parent = np.full(2 * F_count - 1, -1)
    parent[merges["children"].ravel()] = np.repeat(np.arange(F_count, 2 * F_count - 1), 2)
    labels = h.cut(3)
    for label in range(3):
        faces = np.flatnonzero(labels == label)
        node = faces[0]
        while node < F_count or merges["face_count"][node - F_count] < len(faces):
            node = parent[node]
        row = node - F_count
        assert merges["face_count"][row] == len(faces)
        assert merges["rms"][row] < 1e-9
        if regions[faces[0]] == 0:  # the tube
            assert merges["type"][row] == "cylinder"
            assert abs(merges["radius"][row] - 2.0) < 1e-6
            assert np.allclose(np.abs(merges["axis"][row]), [0, 0, 1], atol=1e-9)
        else:
            assert merges["type"][row] == "plane"
            assert np.allclose(np.abs(merges["axis"][row]), [0, 0, 1], atol=1e-9)
            assert min(abs(merges["point"][row][2] - z) for z in (0.5, 5.5)) < 1e-9
    # Components are joined by trailing merges, last, with no fit.
    two = primseg.segment(np.vstack([V, V + [10, 0, 0]]), np.vstack([F, F + len(V)]))
    last = two.merges()
    assert last["trailing"].tolist() == [False] * (len(last["type"]) - 1) + [True]
    assert last["type"][-1] == "" and np.isnan(last["rms"][-1])


def test_sphere_radius_and_centre():
    phi, theta = np.meshgrid(np.linspace(0.2, np.pi - 0.2, 12), np.linspace(0, 2 * np.pi, 24, endpoint=False))
    points = np.stack([np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), np.cos(phi)], -1)
    V = 3.0 * points.reshape(-1, 3) + [10, 20, 30]
    rows, cols = phi.shape  # theta along rows (periodic), phi along columns
    F = []
    for r in range(rows):
        for c in range(cols - 1):
            a, b = r * cols + c, ((r + 1) % rows) * cols + c
            F += [[a, b, b + 1], [a, b + 1, a + 1]]
    clusters = primseg.segment(V, np.array(F), primitives=("sphere",)).clusters(1)
    assert len(clusters) == 1 and clusters[0]["type"] == "sphere"
    assert abs(clusters[0]["params"]["radius"] - 3.0) < 1e-9
    assert np.allclose(clusters[0]["params"]["center"], [10, 20, 30], atol=1e-9)


def bowl(noise, seed=1, rings=12, around=48):
    """A hemispherical shell about (0.3, -0.2, 0.5): outer radius 1, inner 0.8, a flat rim between
    them; each sphere vertex moved along its radius by Gaussian noise of deviation `noise`."""
    rng = np.random.default_rng(seed)
    centre = np.array([0.3, -0.2, 0.5])
    V, F = [], []
    for radius in (1.0, 0.8):
        pole = len(V)
        polar = np.repeat(np.pi / 2 * np.arange(1, rings + 1) / rings, around)
        azimuth = np.tile(2 * np.pi * np.arange(around) / around, rings)
        r = radius + rng.normal(0, noise, rings * around) * (polar < np.pi / 2)
        V += [centre + [0, 0, -radius - rng.normal(0, noise)]]
        V += list(centre + r[:, None] * np.stack([np.sin(polar) * np.cos(azimuth),
                                                  np.sin(polar) * np.sin(azimuth), -np.cos(polar)], -1))
        def vertex(i, j, pole=pole):
            return pole + 1 + (i - 1) * around + j % around
        F += [[pole, vertex(1, j + 1), vertex(1, j)] for j in range(around)]
        F += [t for i in range(1, rings) for j in range(around)
              for t in ([vertex(i, j), vertex(i, j + 1), vertex(i + 1, j + 1)],
                        [vertex(i, j), vertex(i + 1, j + 1), vertex(i + 1, j)])]
    rim_outer, rim_inner = 1 + (rings - 1) * around, len(V) - around
    F += [t for j in range(around)
          for t in ([rim_outer + j, rim_inner + j, rim_inner + (j + 1) % around],
                    [rim_outer + j, rim_inner + (j + 1) % around, rim_outer + (j + 1) % around])]
    return np.array(V), np.array(F)


def test_a_bowls_two_sides_are_concentric():
    tree = primseg.segment(*bowl(noise=0.002))
    assert {"kind": "concentric", "clusters": [0, 1], "deviation": pytest.approx(0, abs=0.002)} in tree.relations(3)
    outer, inner, rim = tree.clusters(3, regularize=True)
    assert (outer["type"], inner["type"], rim["type"]) == ("sphere", "sphere", "plane")
    assert outer["params"]["center"] == inner["params"]["center"]
    assert np.allclose(outer["params"]["center"], [0.3, -0.2, 0.5], atol=0.002)
    assert outer["params"]["radius"] == pytest.approx(1.0, abs=0.002)
    assert inner["params"]["radius"] == pytest.approx(0.8, abs=0.002)


def test_tolerance_levels(fandisk_tree):
    diagonal = fandisk_tree.mesh.bounding_box_diagonal
    np.testing.assert_array_equal(fandisk_tree.cut(relative_tolerance=0.002),
                                  fandisk_tree.cut(tolerance=0.002 * diagonal))
    coarse, fine = fandisk_tree.cut(tolerance=1e-2), fandisk_tree.cut(tolerance=1e-4)
    assert coarse.max() < fine.max()
    assert fandisk_tree.cut(tolerance=0.0).max() + 1 >= fine.max() + 1


def test_options_are_applied(fandisk_tree):
    mesh = fandisk_tree.mesh
    planes = primseg.segment(mesh, primitives="plane")
    assert planes.primitives == ("plane",)
    assert {c["type"] for c in planes.clusters(30)} == {"plane"}
    uniform = primseg.segment(mesh, weights="uniform")
    assert uniform.weights == "uniform" and fandisk_tree.weights == "area"
    assert not np.array_equal(uniform.linkage(), fandisk_tree.linkage())


def test_deterministic_for_any_thread_count(fandisk_tree):
    mesh = fandisk_tree.mesh
    for threads in (1, 2, 3):
        np.testing.assert_array_equal(primseg.segment(mesh, threads=threads).linkage(),
                                      fandisk_tree.linkage())
    np.testing.assert_array_equal(primseg.segment(mesh, eager=True).linkage(), fandisk_tree.linkage())


@pytest.mark.parametrize("option, bad_values", [
    ({"merge_batch_tolerance": 0.1}, (-0.1, float("nan"))),
    ({"regions": 2}, (0, 257)),
])
def test_an_approximate_order_is_the_same_for_any_thread_count(fandisk_tree, option, bad_values):
    mesh = fandisk_tree.mesh
    approximate = primseg.segment(mesh, threads=1, **option)
    np.testing.assert_array_equal(
        primseg.segment(mesh, threads=2, **option).linkage(), approximate.linkage())
    assert not np.array_equal(approximate.linkage(), fandisk_tree.linkage())
    # The coarse levels are the exact order's.
    np.testing.assert_array_equal(approximate.cut(10), fandisk_tree.cut(10))
    (name,) = option
    for bad in bad_values:
        with pytest.raises(primseg.InvalidInputError, match=name):
            primseg.segment(mesh, **{name: bad})


def test_regions_are_no_reference_mode(fandisk_tree):
    with pytest.raises(primseg.InvalidInputError, match="regions"):
        primseg.segment(fandisk_tree.mesh, regions=2, exact_costs=True)


def test_segment_releases_the_gil(fandisk_tree):
    mesh = fandisk_tree.mesh
    assert_releases_the_gil(lambda: primseg.segment(mesh, threads=1))


def test_progress_reports_the_fraction_done_and_can_stop_the_build(fandisk_tree):
    mesh = fandisk_tree.mesh
    fractions = []
    tree = primseg.segment(mesh, progress=fractions.append)
    assert fractions[0] == 0 and fractions[-1] == 1
    assert fractions == sorted(fractions) and len(fractions) >= 50
    np.testing.assert_array_equal(tree.linkage(), fandisk_tree.linkage())

    seen = []

    def stop_at_a_tenth(fraction):
        seen.append(fraction)
        if fraction >= 0.1:
            raise RuntimeError("stopped by the user")

    with pytest.raises(RuntimeError, match="stopped by the user"):
        primseg.segment(mesh, progress=stop_at_a_tenth)
    assert seen[-1] >= 0.1 and all(f < 0.1 for f in seen[:-1])  # no call after the one that raised
    with pytest.raises(ValueError, match="progress must be None or callable, not 3"):
        primseg.segment(mesh, progress=3)


@pytest.mark.parametrize("build", [
    lambda mesh, **kw: primseg.segment(mesh, **kw),
    lambda mesh, **kw: primseg.skeleton(mesh, k=10, **kw),
    lambda mesh, **kw: primseg.denoise(mesh, k=10, iterations=2, **kw)],
    ids=["segment", "skeleton", "denoise"])
def test_ctrl_c_stops_the_build(cgal_mesh, build):
    # SIGINT from another thread while the C++ loop runs without the GIL, as Ctrl-C in a terminal
    # or a notebook: Python's handler runs at the next percent of merges and its KeyboardInterrupt
    # stops the build there. Before, the build ran to its end and the interrupt came after it.
    # (progress is a builtin: calling it runs no Python code, so no handler either.)
    mesh = primseg.read_mesh(cgal_mesh("bunny00.off"))

    def interrupt_soon():
        time.sleep(0.1)  # the whole build takes about 0.6 s on one thread
        os.kill(os.getpid(), signal.SIGINT)

    fractions = []
    killer = threading.Thread(target=interrupt_soon)
    killer.start()
    with pytest.raises(KeyboardInterrupt):
        build(mesh, threads=1, progress=fractions.append)
    killer.join()
    assert 1 not in fractions, len(fractions)  # stopped before the end (maybe before any call)


def test_polygon_file_labels_match_the_cli(cli, tmp_path):
    # The capped cylinder with quads along the tube and one 48-gon per cap.
    around, rings = 48, 8
    V, _, _ = capped_cylinder(around=around, rings=rings)
    V = V[:-2]  # no cap centres: the caps are single polygons
    quads = [[r * around + i, r * around + (i + 1) % around, (r + 1) * around + (i + 1) % around,
              (r + 1) * around + i] for r in range(rings) for i in range(around)]
    caps = [list(range(around))[::-1], list(range(rings * around, (rings + 1) * around))]
    lines = ["OFF", f"{len(V)} {len(quads) + 2} 0"] + [" ".join(map(repr, v)) for v in V.tolist()]
    lines += [" ".join(map(str, [len(f), *f])) for f in quads + caps]
    (tmp_path / "tube.off").write_text("\n".join(lines) + "\n")
    mesh = primseg.read_mesh(tmp_path / "tube.off")
    assert mesh.face_count == len(quads) + 2 and mesh.triangle_count == 2 * len(quads) + 2 * (around - 2)
    h = primseg.segment(mesh)
    run_cli(cli, "segment", tmp_path / "tube.off", "--clusters", "3", "--labels", tmp_path / "l.txt", "--quiet")
    labels = h.cut(3)
    np.testing.assert_array_equal(labels, np.loadtxt(tmp_path / "l.txt"))
    assert same_partition(labels, [0] * len(quads) + [1, 2])
    assert sorted(c["type"] for c in h.clusters(3)) == ["cylinder", "plane", "plane"]


def test_error_curve_matches_the_cli(cli, fandisk, fandisk_tree, tmp_path):
    run_cli(cli, "segment", fandisk, "--curve", tmp_path / "curve.csv", "--quiet")
    expected = np.loadtxt(tmp_path / "curve.csv", delimiter=",", skiprows=1)
    curve = fandisk_tree.error_curve()
    assert curve.dtype == np.float64 and curve.shape == (12946, 2)
    np.testing.assert_array_equal(curve, expected)  # %.17g round-trips
    np.testing.assert_array_equal(curve[:, 0], np.arange(1, 12947))
    assert curve[0, 1] > 0 and curve[-1, 1] == 0  # single faces fit their planes exactly


def test_auto_level_matches_the_cli(cli, fandisk, fandisk_tree, tmp_path):
    run_cli(cli, "segment", fandisk, "--clusters", "auto", "--json", tmp_path / "c.json", "--quiet")
    level = json.loads((tmp_path / "c.json").read_text())["level"]
    auto = fandisk_tree.auto_level()
    assert auto == {"clusters": level["clusters"], "rule": level["rule"],
                    "candidates": level["candidates"]}
    assert fandisk_tree.cut("auto").max() + 1 == auto["clusters"]
    assert auto["rule"] == "knee"  # fandisk's curve has no jump (README, Measured quality)


def test_render_gives_the_cli_picture(cli, fandisk, fandisk_tree, tmp_path):
    run_cli(cli, "segment", fandisk, "--clusters", "30", "--png", tmp_path / "cli.png", "--quiet")
    picture = primseg.render(fandisk_tree, labels=fandisk_tree.cut(30), borders=True,
                             path=tmp_path / "py.png")
    assert (tmp_path / "py.png").read_bytes() == (tmp_path / "cli.png").read_bytes()
    # The lines between clusters darken a few percent of the part's pixels.
    plain = primseg.render(fandisk_tree, labels=fandisk_tree.cut(30))
    part = np.any(plain != 255, axis=2)
    lined = np.any(plain != picture, axis=2)
    assert 0.01 * part.sum() < lined.sum() < 0.2 * part.sum()
    assert np.all(picture[lined].sum(axis=1) < plain[lined].sum(axis=1))
    assert picture.dtype == np.uint8 and picture.shape == (600, 800, 3)
    assert len(np.unique(picture.reshape(-1, 3), axis=0)) > 30  # clusters, shading, background
    assert np.array_equal(picture[0, 0], [255, 255, 255])  # the corner is background
    grey = primseg.render(fandisk_tree.mesh, width=64, height=48, view=(0, 0, -1), edges=True)
    assert grey.shape == (48, 64, 3)
    channels = grey[grey.sum(axis=2) < 3 * 255].astype(int)  # the part's pixels are grey
    assert len(channels) > 0 and np.all(channels[:, 0] == channels[:, 1])
    for bad in ({"width": 0}, {"height": 20000}):
        with pytest.raises(ValueError):
            primseg.render(fandisk_tree, **bad)
