"""python/primseg.pyi against the module it describes: every public name, and for every function
and method its parameters (names, order, keyword-only marker, defaults) as pybind11 itself lists
them. A stub that drifts from the module fails here, not in a user's type checker."""

import ast
import importlib.util
import inspect
import math
import pathlib
import re

import pytest

import primseg

STUB = pathlib.Path(__file__).resolve().parents[1] / "primseg.pyi"
# Dunder methods the module defines on purpose (pickling, copies) and so the stub must too.
SPECIAL = {"__init__", "__getstate__", "__setstate__", "__copy__", "__deepcopy__"}


def stub_tree():
    return ast.parse(STUB.read_text(), filename=str(STUB))


def public(names):
    return {n for n in names if not n.startswith("_")}


def definitions(body):
    """name -> list of the FunctionDef nodes of that name (overloads in order); classes apart."""
    functions, classes = {}, {}
    for node in body:
        if isinstance(node, ast.FunctionDef):
            functions.setdefault(node.name, []).append(node)
        elif isinstance(node, ast.ClassDef):
            classes[node.name] = node
    return functions, classes


def runtime_parameters(function):
    """The parameters pybind11 lists for `function` when called wrongly: (name, kind, default)."""
    try:
        function(no_such_argument_for_the_stub_test=1)
    except TypeError as error:
        message = str(error)
    else:
        raise AssertionError(f"{function} accepted an unknown keyword")
    match = re.search(r"^\s*1\. (?:[\w.]+)?\((.*)\)(?: -> .*)?$", message, re.MULTILINE)
    assert match, message
    # Its annotations (C++-derived, such as List[float[3]]) parse as Python; only names, kinds and
    # defaults are compared.
    return parameters(ast.parse(f"def f({match.group(1)}): pass").body[0])


def parameters(node):
    arguments = node.args
    positional = arguments.posonlyargs + arguments.args
    defaults = [None] * (len(positional) - len(arguments.defaults)) + list(arguments.defaults)
    result = [(a.arg, "positional", d) for a, d in zip(positional, defaults)]
    result += [(a.arg, "keyword", d) for a, d in zip(arguments.kwonlyargs, arguments.kw_defaults)]
    return [(name, kind, None if d is None else value_of(d)) for name, kind, d in result
            if name != "self"]


def value_of(node):
    value = ast.literal_eval(node)
    return list(value) if isinstance(value, tuple) else value


def same_default(a, b):
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same_default(x, y) for x, y in zip(a, b))
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        return math.isclose(a, b, rel_tol=0, abs_tol=0)
    return a == b


def check_signature(where, runtime, overloads):
    """The first definition must be the runtime's signature; later overloads (narrower literal
    types) keep its parameter names in order."""
    first = parameters(overloads[0])
    assert [(n, k) for n, k, _ in first] == [(n, k) for n, k, _ in runtime], where
    for (name, _, stub_default), (_, _, runtime_default) in zip(first, runtime):
        assert same_default(stub_default, runtime_default), (
            f"{where}: default of {name}: stub {stub_default!r}, module {runtime_default!r}")
    for overload in overloads[1:]:
        assert [n for n, _, _ in parameters(overload)] == [n for n, _, _ in runtime], where


def test_the_stub_has_every_public_name_and_no_other():
    functions, classes = definitions(stub_tree().body)
    module_names = public(dir(primseg))
    assert public(functions) | public(classes) == module_names
    assert "__version__" in STUB.read_text()


def test_every_function_has_the_modules_parameters():
    functions, _ = definitions(stub_tree().body)
    for name, overloads in functions.items():
        if name.startswith("_"):
            continue
        check_signature(name, runtime_parameters(getattr(primseg, name)), overloads)


def test_every_class_has_the_modules_members_and_parameters():
    _, classes = definitions(stub_tree().body)
    for class_name, node in classes.items():
        runtime_class = getattr(primseg, class_name)
        runtime_bases = [b.__name__ for b in runtime_class.__bases__ if b.__name__ != "pybind11_object"]
        stub_bases = [ast.unparse(b) for b in node.bases]
        assert stub_bases == runtime_bases, class_name
        if issubclass(runtime_class, BaseException):
            continue
        methods, _ = definitions(node.body)
        runtime_members = {n for n in vars(runtime_class)
                           if not n.startswith("_") or n in SPECIAL}
        if "__init__" not in vars(runtime_class) or runtime_class.__init__.__doc__.startswith("Initialize"):
            runtime_members.discard("__init__")  # pybind11's default: not constructible
        assert set(methods) == runtime_members, class_name
        for name, overloads in methods.items():
            where = f"{class_name}.{name}"
            member = inspect.getattr_static(runtime_class, name)
            is_property = any(ast.unparse(d) == "property" for d in overloads[0].decorator_list)
            assert is_property == isinstance(member, property), where
            if is_property or name in ("__copy__", "__deepcopy__", "__getstate__", "__setstate__"):
                continue
            function = runtime_class if name == "__init__" else getattr(runtime_class, name)
            check_signature(where, runtime_parameters(function), overloads)


@pytest.mark.skipif(importlib.util.find_spec("mypy") is None,
                    reason="mypy missing (apt-get install python3-mypy)")
def test_mypy_accepts_the_stub_and_a_typed_use_of_it(tmp_path, monkeypatch):
    from mypy import api

    monkeypatch.setenv("MYPYPATH", str(STUB.parent))

    use = tmp_path / "use.py"
    use.write_text(
        "import numpy as np\n"
        "from numpy.typing import NDArray\n"
        "import primseg\n"
        "mesh: primseg.Mesh = primseg.read_mesh('part.off')\n"
        "tree: primseg.Hierarchy = primseg.segment(mesh, primitives=['plane'], progress=print)\n"
        "labels: NDArray[np.int32] = tree.cut('auto', refine=2)\n"
        "levels: list[dict[str, object]] = tree.relations_of_levels(range(1, 11), threads=2)\n"
        "V: NDArray[np.float64] = primseg.denoise(tree, k=30)\n"
        "V2, rounds = primseg.denoise(mesh, k=30, return_rounds=True)\n"
        "first: dict[str, object] = rounds[0]\n"
        "V3, level = primseg.denoise(mesh, k='auto', return_level=True)\n"
        "V4, rounds4, level4 = primseg.denoise(mesh, k=30, return_rounds=True, return_level=True)\n"
        "clusters: list[dict[str, object]] = level['clusters'] + level4['clusters']\n"
        "data, indices, indptr = primseg.skeleton(mesh, k=12).skin_weights(sparse=True)\n"
        "rms: float = primseg.distance(mesh, (V, mesh.F))['symmetric']['rms']\n"
        "picture: NDArray[np.uint8] = primseg.render(mesh, labels=labels)\n"
    )
    wrong = tmp_path / "wrong.py"
    wrong.write_text(
        "import primseg\n"
        "primseg.segment(primseg.read_mesh('part.off'), weight='area')\n"
        "n: str = primseg.read_mesh('part.off').face_count\n"
    )
    common = ["--no-incremental", "--cache-dir", str(tmp_path / "cache"), "--strict"]
    # Strict on the snippet and on the stub it imports (MYPYPATH's modules are checked too).
    report, errors, status = api.run([*common, str(use)])
    assert status == 0, report + errors
    report, errors, status = api.run([*common, str(wrong)])
    assert status == 1
    assert 'Unexpected keyword argument "weight"' in report, report
    assert 'Incompatible types in assignment (expression has type "int"' in report, report
