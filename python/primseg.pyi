# Type stubs of the primseg extension module (python/module.cpp and the *_binding.cpp it calls), for
# type checkers and editors.
# Installed beside the module. python/tests/test_stubs.py checks every name, parameter, keyword-only
# marker and default here against the module itself; the docstrings (help(primseg)) say what
# each one means.

import os
from collections.abc import Callable, Mapping, Sequence
from typing import Any, Literal, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

__version__: str

_Path = str | os.PathLike[str]
# A number of clusters, or "auto" (the automatic level).
_Level = int | Literal["auto"] | None
# Called with the fraction done, 0 to 1; an exception it raises stops the work.
_Progress = Callable[[float], object] | None
_Primitives = str | Sequence[str]
_Weights = Literal["area", "uniform"]
# A Mesh, a Hierarchy (its mesh) or a (V, F) pair.
_Surface = Mesh | Hierarchy | tuple[ArrayLike, ArrayLike]
# The CLI's pose file as json.load gives it, or its list of rotations.
_Pose = Mapping[str, Any] | Sequence[Mapping[str, Any] | tuple[int, Sequence[float], float]]

class Error(RuntimeError): ...
class InvalidInputError(Error, ValueError): ...
class IoError(Error, OSError): ...
class ParseError(Error): ...

class Mesh:
    def __init__(self, V: ArrayLike, F: ArrayLike) -> None: ...
    @property
    def V(self) -> NDArray[np.float64]: ...
    @property
    def F(self) -> NDArray[np.int32]: ...
    @property
    def face_of_triangle(self) -> NDArray[np.int32]: ...
    @property
    def face_count(self) -> int: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def triangle_count(self) -> int: ...
    @property
    def bounding_box_diagonal(self) -> float: ...
    def info(self, *, noise: bool = False) -> dict[str, Any]: ...
    def __copy__(self) -> Mesh: ...
    def __deepcopy__(self, memo: dict[Any, Any]) -> Mesh: ...
    def __getstate__(self) -> tuple[bytes, bytes, bytes, bytes, bytes]: ...
    def __setstate__(self, state: tuple[bytes, bytes, bytes, bytes, bytes]) -> None: ...

class Hierarchy:
    def cut(
        self,
        k: _Level = None,
        *,
        tolerance: float | None = None,
        relative_tolerance: float | None = None,
        refine: int = 0,
    ) -> NDArray[np.int32]: ...
    def clusters(
        self,
        k: _Level = None,
        *,
        tolerance: float | None = None,
        relative_tolerance: float | None = None,
        refine: int = 0,
        regularize: bool = False,
        relation_significance: float = 3.0,
        max_relation_angle: float = 20.0,
        relation_angle_tolerance: float = 0.0,
        relation_length_tolerance: float | str = 0.0,
        max_radius_difference: float = 0.05,
    ) -> list[dict[str, Any]]: ...
    def borders(
        self,
        k: _Level = None,
        *,
        tolerance: float | None = None,
        relative_tolerance: float | None = None,
        refine: int = 0,
        regularize: bool = False,
        relation_significance: float = 3.0,
        max_relation_angle: float = 20.0,
        relation_angle_tolerance: float = 0.0,
        relation_length_tolerance: float | str = 0.0,
        max_radius_difference: float = 0.05,
    ) -> list[dict[str, Any]]: ...
    def relations(
        self,
        k: _Level = None,
        *,
        tolerance: float | None = None,
        relative_tolerance: float | None = None,
        refine: int = 0,
        relation_significance: float = 3.0,
        max_relation_angle: float = 20.0,
        relation_angle_tolerance: float = 0.0,
        relation_length_tolerance: float | str = 0.0,
        max_radius_difference: float = 0.05,
    ) -> list[dict[str, Any]]: ...
    def relations_of_levels(
        self,
        ks: Sequence[int] | NDArray[np.integer[Any]],
        *,
        relation_significance: float = 3.0,
        max_relation_angle: float = 20.0,
        relation_angle_tolerance: float = 0.0,
        relation_length_tolerance: float | str = 0.0,
        max_radius_difference: float = 0.05,
        threads: int = 0,
    ) -> list[dict[str, Any]]: ...
    def auto_level(self) -> dict[str, Any]: ...
    def error_curve(self) -> NDArray[np.float64]: ...
    def linkage(self) -> NDArray[np.float64]: ...
    def merges(self) -> dict[str, NDArray[Any]]: ...
    def save(self, path: _Path) -> None: ...
    @property
    def mesh(self) -> Mesh: ...
    @property
    def face_count(self) -> int: ...
    @property
    def component_count(self) -> int: ...
    @property
    def primitives(self) -> tuple[str, ...]: ...
    @property
    def weights(self) -> _Weights: ...
    def __copy__(self) -> Hierarchy: ...
    def __deepcopy__(self, memo: dict[Any, Any]) -> Hierarchy: ...
    def __getstate__(self) -> tuple[bytes]: ...
    def __setstate__(self, state: tuple[bytes]) -> None: ...

class Skeleton:
    @property
    def bones(self) -> list[dict[str, Any]]: ...
    @property
    def joints(self) -> list[dict[str, Any]]: ...
    @property
    def joint_positions(self) -> NDArray[np.float64]: ...
    @property
    def face_labels(self) -> NDArray[np.int32]: ...
    @property
    def cluster_count(self) -> int: ...
    @property
    def root_bone(self) -> int: ...
    @property
    def mesh(self) -> Mesh: ...
    def bones_beyond(self, joint: int) -> list[int]: ...
    @overload
    def skin_weights(self, band: float = 0.5, sparse: Literal[False] = False) -> NDArray[np.float64]: ...
    @overload
    def skin_weights(
        self, band: float = 0.5, *, sparse: Literal[True]
    ) -> tuple[NDArray[np.float64], NDArray[np.int32], NDArray[np.int32]]: ...
    def deform(self, pose: _Pose, band: float = 0.5) -> NDArray[np.float64]: ...
    def gltf(self, band: float = 0.5, max_influences: int = 0) -> bytes: ...
    def posed_joint_positions(self, pose: _Pose) -> NDArray[np.float64]: ...
    def to_dict(self) -> dict[str, Any]: ...
    def save(self, path: _Path) -> None: ...
    def __copy__(self) -> Skeleton: ...
    def __deepcopy__(self, memo: dict[Any, Any]) -> Skeleton: ...
    def __getstate__(self) -> tuple[tuple[bytes, bytes, bytes, bytes, bytes], bytes]: ...
    def __setstate__(self, state: tuple[tuple[bytes, bytes, bytes, bytes, bytes], bytes]) -> None: ...

def read_mesh(path: _Path) -> Mesh: ...
def read_skeleton(
    path: _Path, mesh_or_V: Mesh | Hierarchy | ArrayLike, F: ArrayLike | None = None
) -> Skeleton: ...
def read_tree(path: _Path) -> Hierarchy: ...
def write_mesh(
    path: _Path,
    mesh_or_V: Mesh | Hierarchy | ArrayLike,
    F: ArrayLike | None = None,
    *,
    positions: ArrayLike | None = None,
    labels: ArrayLike | None = None,
    binary: bool = True,
) -> None: ...
def segment(
    mesh_or_V: Mesh | ArrayLike,
    F: ArrayLike | None = None,
    *,
    primitives: _Primitives = ("plane", "cylinder", "sphere"),
    weights: _Weights = "area",
    threads: int = 0,
    exact_costs: bool = False,
    eager: bool = False,
    merge_batch_tolerance: float = 0.0,
    regions: int = 1,
    progress: _Progress = None,
) -> Hierarchy: ...
def render(
    mesh_or_V: Mesh | Hierarchy | ArrayLike,
    F: ArrayLike | None = None,
    *,
    labels: ArrayLike | None = None,
    width: int = 800,
    height: int = 600,
    view: Sequence[float] = (-1.0, -0.8, -1.3),
    up: Sequence[float] = (0.0, 1.0, 0.0),
    edges: bool = False,
    borders: bool = False,
    path: _Path | None = None,
) -> NDArray[np.uint8]: ...
@overload
def denoise(
    mesh_or_V: Mesh | Hierarchy | ArrayLike,
    F: ArrayLike | None = None,
    *,
    k: _Level = None,
    tolerance: float | None = None,
    relative_tolerance: float | None = None,
    iterations: int = 1,
    smoothing_steps: int = 0,
    bilateral: bool = False,
    stylize: bool = False,
    max_move: float = 4.0,
    min_crease_angle: float = 10.0,
    relabel_passes: int = 2,
    relation_significance: float = 3.0,
    noise_tolerance_factor: float | None = None,
    ensemble: int = 1,
    ensemble_jitter: float = 0.3,
    primitives: _Primitives | None = None,
    weights: _Weights | None = None,
    threads: int = 0,
    regions: int = 1,
    return_rounds: Literal[False] = False,
    return_level: Literal[False] = False,
    progress: _Progress = None,
) -> NDArray[np.float64]: ...
@overload
def denoise(
    mesh_or_V: Mesh | Hierarchy | ArrayLike,
    F: ArrayLike | None = None,
    *,
    k: _Level = None,
    tolerance: float | None = None,
    relative_tolerance: float | None = None,
    iterations: int = 1,
    smoothing_steps: int = 0,
    bilateral: bool = False,
    stylize: bool = False,
    max_move: float = 4.0,
    min_crease_angle: float = 10.0,
    relabel_passes: int = 2,
    relation_significance: float = 3.0,
    noise_tolerance_factor: float | None = None,
    ensemble: int = 1,
    ensemble_jitter: float = 0.3,
    primitives: _Primitives | None = None,
    weights: _Weights | None = None,
    threads: int = 0,
    regions: int = 1,
    return_rounds: Literal[True],
    return_level: Literal[False] = False,
    progress: _Progress = None,
) -> tuple[NDArray[np.float64], list[dict[str, Any]]]: ...
@overload
def denoise(
    mesh_or_V: Mesh | Hierarchy | ArrayLike,
    F: ArrayLike | None = None,
    *,
    k: _Level = None,
    tolerance: float | None = None,
    relative_tolerance: float | None = None,
    iterations: int = 1,
    smoothing_steps: int = 0,
    bilateral: bool = False,
    stylize: bool = False,
    max_move: float = 4.0,
    min_crease_angle: float = 10.0,
    relabel_passes: int = 2,
    relation_significance: float = 3.0,
    noise_tolerance_factor: float | None = None,
    ensemble: int = 1,
    ensemble_jitter: float = 0.3,
    primitives: _Primitives | None = None,
    weights: _Weights | None = None,
    threads: int = 0,
    regions: int = 1,
    return_rounds: Literal[False] = False,
    return_level: Literal[True],
    progress: _Progress = None,
) -> tuple[NDArray[np.float64], dict[str, Any]]: ...
@overload
def denoise(
    mesh_or_V: Mesh | Hierarchy | ArrayLike,
    F: ArrayLike | None = None,
    *,
    k: _Level = None,
    tolerance: float | None = None,
    relative_tolerance: float | None = None,
    iterations: int = 1,
    smoothing_steps: int = 0,
    bilateral: bool = False,
    stylize: bool = False,
    max_move: float = 4.0,
    min_crease_angle: float = 10.0,
    relabel_passes: int = 2,
    relation_significance: float = 3.0,
    noise_tolerance_factor: float | None = None,
    ensemble: int = 1,
    ensemble_jitter: float = 0.3,
    primitives: _Primitives | None = None,
    weights: _Weights | None = None,
    threads: int = 0,
    regions: int = 1,
    return_rounds: Literal[True],
    return_level: Literal[True],
    progress: _Progress = None,
) -> tuple[NDArray[np.float64], list[dict[str, Any]], dict[str, Any]]: ...
def skeleton(
    mesh_or_V: Mesh | Hierarchy | ArrayLike,
    F: ArrayLike | None = None,
    *,
    k: _Level = None,
    tolerance: float | None = None,
    relative_tolerance: float | None = None,
    primitives: _Primitives | None = None,
    weights: _Weights | None = None,
    joints: Literal["paper", "limbs"] = "paper",
    threads: int = 0,
    regions: int = 1,
    progress: _Progress = None,
) -> Skeleton: ...
def distance(
    a: _Surface,
    b: _Surface,
    *,
    samples: int | None = None,
    density: float | None = None,
    seed: int = 1,
    threads: int = 0,
) -> dict[str, Any]: ...
