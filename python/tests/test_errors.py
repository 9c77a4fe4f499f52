"""Every bad input raises a Python exception with a clear message, never a crash."""

import numpy as np
import pytest

import primseg

V_OK = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
F_OK = np.array([[0, 1, 2], [1, 3, 2]])


def test_exception_hierarchy():
    assert issubclass(primseg.Error, RuntimeError)
    assert issubclass(primseg.IoError, primseg.Error) and issubclass(primseg.IoError, OSError)
    assert issubclass(primseg.ParseError, primseg.Error)
    assert issubclass(primseg.ParseError, RuntimeError)
    assert issubclass(primseg.InvalidInputError, primseg.Error)
    assert issubclass(primseg.InvalidInputError, ValueError)


def test_a_call_with_wrong_arguments_names_python_types_only():
    # pybind11's TypeError lists each overload's signature; a class registered after a function
    # that returns it would show there as its C++ name (read_skeleton did, until session 37).
    mesh = primseg.Mesh(V_OK, F_OK)
    targets = []
    for owner in (primseg, mesh, primseg.segment(mesh), primseg.skeleton(mesh, k=1)):
        for name in dir(owner):
            member = getattr(owner, name)
            if not name.startswith("_") and callable(member) and not isinstance(member, type):
                targets.append(member)
    assert len(targets) > 25
    for function in targets:
        with pytest.raises(TypeError) as raised:
            function(object(), object(), object(), object(), object(), object())
        assert "primseg::" not in str(raised.value), str(raised.value)


BAD_ARRAYS = {
    "V 1-D": (np.zeros(9), F_OK, r"V must have shape \(n, 3\), not \(9,\)"),
    "V (n, 2)": (np.zeros((4, 2)), F_OK, r"V must have shape \(n, 3\), not \(4, 2\)"),
    "V (n, 4)": (np.zeros((4, 4)), F_OK, r"V must have shape \(n, 3\), not \(4, 4\)"),
    "V 3-D": (np.zeros((4, 3, 1)), F_OK, r"V must have shape \(n, 3\), not \(4, 3, 1\)"),
    "V int": (V_OK.astype(np.int64), F_OK, "V must be an array of float32 or float64, not 'int64'"),
    "V float16": (V_OK.astype(np.float16), F_OK, "not 'float16'"),
    "V complex": (V_OK.astype(np.complex128), F_OK, "not 'complex128'"),
    "V strings": (V_OK.astype(str), F_OK, "V must be an array of float32 or float64"),
    "V object": (V_OK.astype(object), F_OK, "not 'object'"),
    "V NaN": (np.where(np.arange(12).reshape(4, 3) == 7, np.nan, V_OK), F_OK,
              r"V\[2, 1\] is nan: coordinates must be finite"),
    "V inf float32": (np.where(np.arange(12).reshape(4, 3) == 3, np.inf, V_OK).astype(np.float32),
                      F_OK, r"V\[1, 0\] is inf"),
    "V -inf": (np.where(np.arange(12).reshape(4, 3) == 11, -np.inf, V_OK), F_OK, r"V\[3, 2\] is -inf"),
    "F float": (V_OK, F_OK.astype(np.float64), "F must be an array of int32, int64, uint32 or uint64, not 'float64'"),
    "F int16": (V_OK, F_OK.astype(np.int16), "not 'int16'"),
    "F bool": (V_OK, F_OK.astype(bool), "not 'bool'"),
    "F (m, 4)": (V_OK, np.array([[0, 1, 2, 3]]), r"F must have shape \(n, 3\), not \(1, 4\)"),
    "F 1-D": (V_OK, np.array([0, 1, 2]), r"F must have shape \(n, 3\), not \(3,\)"),
    "F empty": (V_OK, np.zeros((0, 3), dtype=np.int32), "F has no faces"),
    "F negative": (V_OK, np.array([[0, 1, -1]]), r"F\[0, 2\] = -1 is not a vertex index \(V has 4 rows\)"),
    "F too large": (V_OK, np.array([[0, 1, 2], [1, 4, 2]]), r"F\[1, 1\] = 4 is not a vertex index"),
    "F int64 beyond 2^32": (V_OK, np.array([[0, 1, 2**32 + 1]]), r"F\[0, 2\] = 4294967297"),
    "F uint64 huge": (V_OK, np.array([[0, 2**64 - 1, 1]], dtype=np.uint64), r"F\[0, 1\] = 18446744073709551615"),
    "F into empty V": (np.zeros((0, 3)), F_OK, r"F\[0, 0\] = 0 is not a vertex index \(V has 0 rows\)"),
    "ragged list": (V_OK, [[0, 1, 2], [1, 2]], None),
}


ENTRY_POINTS = {
    "Mesh": primseg.Mesh,
    "segment": primseg.segment,
    "denoise": lambda V, F: primseg.denoise(V, F, k=1),
    "skeleton": lambda V, F: primseg.skeleton(V, F, k=1),
    "distance a": lambda V, F: primseg.distance((V, F), (V_OK, F_OK)),
    "distance b": lambda V, F: primseg.distance([V_OK, F_OK], [V, F]),
}


@pytest.mark.parametrize("name", BAD_ARRAYS)
@pytest.mark.parametrize("entry_point", ENTRY_POINTS)
def test_bad_arrays_raise_value_error(name, entry_point):
    V, F, message = BAD_ARRAYS[name]
    with pytest.raises(ValueError, match=message) as raised:
        ENTRY_POINTS[entry_point](V, F)
    if name != "ragged list":  # numpy's own ValueError, before primseg sees the data
        assert isinstance(raised.value, primseg.InvalidInputError)


@pytest.mark.parametrize("entry_point", [name for name in ENTRY_POINTS if name != "Mesh"])
def test_coordinates_outside_the_supported_range_raise_value_error(entry_point):
    # A Mesh holds any finite coordinates; the geometry refuses what it cannot compute with.
    far = V_OK.copy()
    far[2, 1] = 1e40
    primseg.Mesh(far, F_OK)
    with pytest.raises(primseg.InvalidInputError, match=r"vertex 2 has a coordinate of magnitude 1e\+40"):
        ENTRY_POINTS[entry_point](far, F_OK)
    with pytest.raises(primseg.InvalidInputError, match=r"the mesh spans 1e-40 units, below the 1e-32"):
        ENTRY_POINTS[entry_point](V_OK * 1e-40, F_OK)


def test_segment_argument_errors(fandisk):
    mesh = primseg.read_mesh(fandisk)
    with pytest.raises(ValueError, match="segment.V, F.: F is missing"):
        primseg.segment(V_OK)
    with pytest.raises(ValueError, match="segment.mesh. takes no F"):
        primseg.segment(mesh, F_OK)
    with pytest.raises(
        ValueError,
        match=r"unknown primitive 'ellipsoid' \(available: 'plane', 'cylinder', 'sphere', 'cone', 'torus'\)",
    ):
        primseg.segment(mesh, primitives=("plane", "ellipsoid"))
    with pytest.raises(ValueError, match="primitives: expected names, got 3"):
        primseg.segment(mesh, primitives=["plane", 3])
    with pytest.raises(ValueError, match="weights: must be 'area' or 'uniform', not 'volume'"):
        primseg.segment(mesh, weights="volume")
    with pytest.raises(ValueError, match="primitive"):
        primseg.segment(mesh, primitives=())
    with pytest.raises(ValueError, match="duplicate|twice|more than once"):
        primseg.segment(mesh, primitives=("plane", "plane"))


def test_level_errors():
    h = primseg.segment(V_OK, F_OK)
    for k in (0, -1, 3, 2**40):
        with pytest.raises(ValueError, match=r"k must be between 1 and the number of faces \(2\), not "):
            h.cut(k)
        with pytest.raises(ValueError, match="k must be between"):
            h.clusters(k)
    with pytest.raises(ValueError, match="at most one of k, tolerance and relative_tolerance"):
        h.cut(1, tolerance=0.1)
    with pytest.raises(ValueError, match="at most one"):
        h.clusters(tolerance=0.1, relative_tolerance=0.1)
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="tolerance"):
            h.cut(tolerance=bad)
        with pytest.raises(ValueError, match="relative_tolerance must be a non-negative number"):
            h.cut(relative_tolerance=bad)
    with pytest.raises(ValueError, match="k must be a number of clusters or 'auto', not '3'"):
        h.cut("3")
    with pytest.raises(TypeError):
        h.cut(3.5)


def test_file_errors(tmp_path, fandisk):
    missing = tmp_path / "missing.off"
    with pytest.raises(OSError, match="missing.off") as raised:
        primseg.read_mesh(missing)
    assert isinstance(raised.value, primseg.IoError)

    truncated = tmp_path / "truncated.off"
    truncated.write_bytes(fandisk.read_bytes()[:20000])
    with pytest.raises(primseg.ParseError, match="truncated.off") as raised:
        primseg.read_mesh(truncated)
    assert isinstance(raised.value, RuntimeError) and not isinstance(raised.value, OSError)

    garbage = tmp_path / "garbage.ply"
    garbage.write_text("not a ply file\n")
    with pytest.raises(primseg.ParseError, match="garbage.ply"):
        primseg.read_mesh(garbage)

    with pytest.raises(ValueError, match="mesh.xyz"):
        primseg.read_mesh(tmp_path / "mesh.xyz")

    nan = tmp_path / "nan.off"
    nan.write_text("OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n")
    with pytest.raises(ValueError):
        primseg.read_mesh(nan)

    with pytest.raises(primseg.ParseError, match="fandisk.off"):
        primseg.read_tree(fandisk)
    with pytest.raises(OSError):
        primseg.read_tree(missing)
    with pytest.raises(OSError):
        primseg.segment(V_OK, F_OK).save(tmp_path / "no" / "such" / "dir" / "t.tree")


def test_relations_of_levels_errors():
    h = primseg.segment(V_OK, F_OK)
    assert h.relations_of_levels([]) == []
    for k in (0, -1, 3, 2**40):
        with pytest.raises(primseg.InvalidInputError,
                           match=rf"ks\[1\]: k must be between 1 and the number of faces \(2\), not {k}$"):
            h.relations_of_levels([1, k])
    for bad in ([1.5], [1, "auto"], "12", 2, [None], np.array([1.0])):
        with pytest.raises(TypeError):
            h.relations_of_levels(bad)
    for bad in (dict(relation_significance=0.0), dict(max_relation_angle=90.0),
                dict(relation_angle_tolerance=float("nan")), dict(relation_length_tolerance=-1.0),
                dict(max_radius_difference=1.0)):
        (keyword,) = bad
        with pytest.raises(ValueError, match=keyword):
            h.relations_of_levels([1], **bad)
    with pytest.raises(TypeError):
        h.relations_of_levels([1], threads=-1)


def test_denoise_argument_errors():
    mesh = primseg.Mesh(V_OK, F_OK)
    with pytest.raises(ValueError, match=r"denoise\(mesh\) takes no F \(give the level as k=...\)"):
        primseg.denoise(mesh, 1)
    with pytest.raises(ValueError, match=r"denoise\(V, F\): F is missing"):
        primseg.denoise(V_OK)
    with pytest.raises(ValueError, match=r"k must be between 1 and the number of faces \(2\), not 3"):
        primseg.denoise(mesh, k=3)
    with pytest.raises(ValueError, match="k must be a number of clusters or 'auto', not 'all'"):
        primseg.denoise(mesh, k="all")
    with pytest.raises(ValueError, match="at most one of k, tolerance and relative_tolerance"):
        primseg.denoise(mesh, k=1, tolerance=0.1)
    with pytest.raises(ValueError, match="tolerance must be a non-negative number"):
        primseg.denoise(mesh, tolerance=float("nan"))
    for bad in (0, -1, 101):
        with pytest.raises(ValueError, match="iterations must be between 1 and 100"):
            primseg.denoise(mesh, iterations=bad)
    for bad in (-1, 101):
        with pytest.raises(ValueError, match="relabel_passes must be between 0 and 100"):
            primseg.denoise(mesh, relabel_passes=bad)
    for option in ({"max_move": 0.0}, {"max_move": float("nan")}, {"min_crease_angle": 90.0},
                   {"min_crease_angle": -1.0}, {"smoothing_steps": -1},
                   {"relation_significance": -1.0}, {"relation_significance": float("inf")},
                   {"k": "auto", "noise_tolerance_factor": 0.0}):
        with pytest.raises(ValueError):
            primseg.denoise(mesh, **option)
    for bad in (0, 65):
        with pytest.raises(ValueError, match=f"ensemble must have 1 to 64 members, not {bad}"):
            primseg.denoise(mesh, ensemble=bad)
    for bad in (0.0, 1.5, float("nan")):
        with pytest.raises(ValueError, match=r"jitter must be in \(0, 1\]"):
            primseg.denoise(mesh, ensemble=2, ensemble_jitter=bad)
    with pytest.raises(ValueError, match="stylize with one member"):
        primseg.denoise(mesh, ensemble=2, stylize=True)
    with pytest.raises(ValueError, match="unknown primitive 'ellipsoid'"):
        primseg.denoise(mesh, primitives="ellipsoid")
    with pytest.raises(ValueError, match="weights: must be 'area' or 'uniform', not 3"):
        primseg.denoise(mesh, weights=3)
    tree = primseg.segment(mesh)
    with pytest.raises(ValueError, match=r"denoise\(hierarchy\): smoothing_steps must be 0"):
        primseg.denoise(tree, smoothing_steps=2)
    with pytest.raises(ValueError, match=r"denoise\(hierarchy\): smoothing_steps must be 0 and bilateral False"):
        primseg.denoise(tree, bilateral=True)
    with pytest.raises(ValueError, match="choose Taubin or bilateral smoothing, not both"):
        primseg.denoise(mesh, smoothing_steps=2, bilateral=True)
    with pytest.raises(ValueError, match="primitives and weights are the hierarchy's"):
        primseg.denoise(tree, primitives="plane")
    with pytest.raises(ValueError, match=r"denoise\(hierarchy\) takes no F"):
        primseg.denoise(tree, F_OK)
    with pytest.raises(TypeError):
        primseg.denoise(mesh, k=1.5)


def test_skeleton_and_pose_errors(cgal_mesh):
    mesh = primseg.Mesh(V_OK, F_OK)
    with pytest.raises(ValueError, match=r"skeleton\(mesh\) takes no F"):
        primseg.skeleton(mesh, 2)
    with pytest.raises(ValueError, match=r"k must be between 1 and the number of faces \(2\), not 0"):
        primseg.skeleton(mesh, k=0)
    with pytest.raises(ValueError, match="unknown primitive"):
        primseg.skeleton(mesh, primitives=("cylinder", "ellipsoid"))
    with pytest.raises(ValueError, match=r"joints='hubs' is not 'paper' or 'limbs'"):
        primseg.skeleton(mesh, joints="hubs")
    skeleton = primseg.skeleton(primseg.read_mesh(cgal_mesh("man.off")), k=20)
    locked = [j["id"] for j in skeleton.joints if j["kind"] != "sensitive"]
    assert locked
    sensitive = [j["id"] for j in skeleton.joints if j["kind"] == "sensitive"][0]
    for band in (-0.1, float("inf"), float("nan")):
        with pytest.raises(ValueError, match="band must be a finite number >= 0"):
            skeleton.skin_weights(band=band)
        with pytest.raises(ValueError, match="band"):
            skeleton.deform([], band=band)
    bad_poses = {
        "not a list": (3, "pose must be a list of rotations"),
        "a string": ("joint 1", "pose must be a list of rotations"),
        "dict without rotations": ({"pose": []}, "must have \"rotations\""),
        "missing key": ([{"joint": sensitive, "axis": [0, 0, 1]}], "pose rotation 0: missing \"degrees\""),
        "short tuple": ([(sensitive, (0, 0, 1))], "pose rotation 0 must be a dict"),
        "negative joint": ([(-1, (0, 0, 1), 10)], "pose rotation 0: joint must be an integer"),
        "float joint": ([(1.0, (0, 0, 1), 10)], "joint must be an integer"),
        "huge joint": ([(2**70, (0, 0, 1), 10)], "joint must be an integer"),
        "unknown joint": ([(len(skeleton.joints), (0, 0, 1), 10)], "joint"),
        "two-component axis": ([(sensitive, (0, 1), 10)], "axis must be 3 numbers"),
        "text axis": ([(sensitive, "xyz", 10)], "axis must be 3 numbers"),
        "NaN axis": ([(sensitive, (0, float("nan"), 1), 10)], "axis must be finite"),
        "zero axis": ([(sensitive, (0, 0, 0), 10)], "axis"),
        "text angle": ([(sensitive, (0, 0, 1), "ten")], "degrees must be a number, not 'ten'"),
        "infinite angle": ([(sensitive, (0, 0, 1), float("inf"))], "degrees must be a finite number"),
        "joint twice": ([(sensitive, (0, 0, 1), 10)] * 2, "twice|more than once|repeated|already"),
    }
    bad_poses["locked joint"] = ([(locked[0], (0, 0, 1), 10)], "sensitive")
    for name, (pose, message) in bad_poses.items():
        with pytest.raises(ValueError, match=message):
            skeleton.deform(pose)
        with pytest.raises(ValueError, match=message):
            skeleton.posed_joint_positions(pose)
    with pytest.raises(ValueError, match="joint must be between 0 and"):
        skeleton.bones_beyond(len(skeleton.joints))
    with pytest.raises(ValueError, match="joint must be between 0 and"):
        skeleton.bones_beyond(-1)


def test_distance_argument_errors():
    with pytest.raises(ValueError, match="a must be a Mesh, a Hierarchy or a \\(V, F\\) pair, not <class 'numpy.ndarray'>"):
        primseg.distance(V_OK, (V_OK, F_OK))
    with pytest.raises(ValueError, match="b must be a Mesh"):
        primseg.distance((V_OK, F_OK), (V_OK, F_OK, None))
    with pytest.raises(ValueError, match="give samples or density, not both"):
        primseg.distance((V_OK, F_OK), (V_OK, F_OK), samples=10, density=1.0)
    for samples in (-1, 2**64, 1.5, "10", True):
        with pytest.raises(ValueError, match="samples must be an integer"):
            primseg.distance((V_OK, F_OK), (V_OK, F_OK), samples=samples)
    with pytest.raises(ValueError, match="sample"):
        primseg.distance((V_OK, F_OK), (V_OK, F_OK), samples=0)
    for density in (-1.0, float("nan"), 1e12):
        with pytest.raises(ValueError, match="density"):
            primseg.distance((V_OK, F_OK), (V_OK, F_OK), density=density)
    with pytest.raises(ValueError, match="seed must be an integer"):
        primseg.distance((V_OK, F_OK), (V_OK, F_OK), seed=-3)
    flat = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    with pytest.raises(ValueError, match="area"):
        primseg.distance((flat, [[0, 1, 2]]), (V_OK, F_OK))
