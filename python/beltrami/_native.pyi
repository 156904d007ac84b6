"""Type stubs of the compiled extension ``beltrami._native`` (python/src/)."""

from os import PathLike
from typing import Any, Callable, Dict, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

Floats = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]
Complexes = npt.NDArray[np.complex128]
Progress = Callable[[str, int, Optional[int], Optional[float]], Any]

def read_mesh(path: Union[str, PathLike[str]]) -> Tuple[Floats, Ints, Optional[Floats]]: ...
def write_mesh(path: Union[str, PathLike[str]], v: Floats, f: Ints, uv: Optional[Floats] = None) -> None: ...
def mesh_info(v: Floats, f: Ints) -> Dict[str, Any]: ...
def beltrami_coefficient(v: Floats, f: Ints, x: Floats) -> Tuple[Complexes, str]: ...
def distortion(v: Floats, f: Ints, x: Floats) -> Dict[str, Any]: ...
def solve(
    solver: str,
    v: Floats,
    f: Ints,
    spec: str,
    boundary_map: Optional[Floats] = None,
    initial: Optional[Floats] = None,
    mu: Optional[Complexes] = None,
    target_v: Optional[Floats] = None,
    target_f: Optional[Ints] = None,
    progress: Optional[Progress] = None,
) -> Dict[str, Any]: ...
def solvers() -> str: ...
def atlas(
    v: Floats,
    f: Ints,
    cones: Optional[int] = None,
    max_stretch: float = 1.1,
    padding: float = 0.004,
    charts: Optional[int] = None,
) -> Tuple[Floats, Ints, str]: ...
def remesh(
    v: Floats,
    f: Ints,
    edge_length: Optional[float] = None,
    vertices: Optional[int] = None,
    param: str = "auto",
    min_angle: float = 30.0,
    size_field: str = "uniform",
    max_vertices: int = 5000000,
    feature_tolerance: float = 0.2,
    components: Optional[str] = None,
) -> Tuple[Floats, Ints, str]: ...
def remesh_in_place(
    v: Floats,
    f: Ints,
    reference: str = "optimized",
    constraint: str = "normal",
    max_iters: int = 10,
    tolerance: float = 1e-4,
    feature_angle: float = 60.0,
    project: bool = True,
    allow_flips: bool = False,
) -> Tuple[Floats, str]: ...
def cut_to_disk(v: Floats, f: Ints) -> Tuple[Floats, Ints, Ints, str]: ...
def repair(
    v: Floats,
    f: Ints,
    merge_vertices: bool = ...,
    drop_degenerate_faces: bool = ...,
    drop_duplicate_faces: bool = ...,
) -> Tuple[Floats, Ints, Ints, Ints, str]: ...
