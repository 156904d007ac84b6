"""Checked by mypy in `.ci/run`, never run: each call's overload gives it its return
type (the map, or the map and the report with ``info=True``)."""

from typing import Any, Dict, Optional, Tuple, assert_type

import numpy as np

import beltrami


def calls(V: np.ndarray, F: np.ndarray) -> None:
    assert_type(beltrami.tutte(V, F), np.ndarray)
    assert_type(beltrami.lscm(V, F, [0, 1], [[0, 0], [1, 0]]), np.ndarray)
    assert_type(beltrami.beltrami_flow(V, F, info=True), Tuple[np.ndarray, Dict[str, Any]])
    assert_type(beltrami.register(V, F, V, F), Tuple[np.ndarray, np.ndarray, np.ndarray])
    assert_type(
        beltrami.register(V, F, V, F, info=True),
        Tuple[np.ndarray, np.ndarray, np.ndarray, Dict[str, Any]],
    )
    assert_type(beltrami.remesh(V, F, vertices=100), Tuple[np.ndarray, np.ndarray])
    assert_type(beltrami.read_mesh("mesh.ply"), Tuple[np.ndarray, np.ndarray])
    assert_type(
        beltrami.read_mesh("mesh.ply", uv=True), Tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]
    )
    assert_type(beltrami.repair(V, F), Tuple[np.ndarray, np.ndarray, Dict[Any, Any]])
