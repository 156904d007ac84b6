"""beltrami: quasiconformal maps of triangle and quad meshes, numpy arrays in and out.

Meshes are given as ``V`` (float64, ``(n, 3)``; ``(n, 2)`` for a planar mesh in z = 0)
and ``F`` (integer, ``(m, 3)`` triangles or ``(m, 4)`` quads, 0-based). Maps come back
as arrays whose rows are the rows of ``V``: ``(n, 2)`` for a map into the plane (texture
coordinates), ``(n, 3)`` for a map into R^3 (the sphere, a target surface). Beltrami
coefficients ``mu = f_zbar / f_z`` are complex, one per row of ``F``.

Every solver call takes the options of the matching ``beltrami`` command as keyword
arguments (``--max-iters`` is ``max_iters``), with the command's defaults, so that a call
and the command give the same map; ``options={"name": value}`` sets any solver option
(``--option NAME=VALUE``; :func:`solvers` lists them). With ``info=True`` a call also
returns the command's JSON report as a dict (``mu_mean``, ``mu_max``, ``flipped``,
``iterations``, ``k``, timings, ...).

Solves run with the GIL released; Ctrl-C stops an iterative solve at its next step
(``KeyboardInterrupt``). Errors are :class:`BeltramiError` subclasses (see
``beltrami._errors``) with the command line's messages.
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Dict, Iterable, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np

from . import _native
from ._errors import (
    BeltramiError,
    ConstraintError,
    FieldError,
    MeshError,
    MeshFileError,
    OptionError,
    SolverError,
    UnsupportedError,
)

__version__ = _native.__version__

ArrayLike = Any
Progress = Callable[[str, int, Optional[int], Optional[float]], None]

__all__ = [
    "BeltramiError",
    "ConstraintError",
    "FieldError",
    "MeshError",
    "MeshFileError",
    "OptionError",
    "SolverError",
    "UnsupportedError",
    "atlas",
    "beltrami_coefficient",
    "beltrami_flow",
    "circle_domain",
    "cut_to_disk",
    "distortion",
    "extremal",
    "harmonic",
    "lscm",
    "lsqc",
    "mesh_info",
    "qc_iteration",
    "read_mesh",
    "register",
    "remesh",
    "remesh_in_place",
    "repair",
    "show",
    "solve",
    "solvers",
    "sphere_map",
    "tutte",
    "weld",
    "write_mesh",
]


# ---- arrays -------------------------------------------------------------------------


def _matrix(name: str, a: ArrayLike, dtype: Any, error: type) -> np.ndarray:
    """``a`` as a 2-D array of ``dtype`` (no copy when it already is one)."""
    try:
        out = np.asarray(a, dtype=dtype)
    except (TypeError, ValueError) as e:
        raise error(f"{name}: {e}") from None
    if out.ndim != 2:
        raise error(f"{name} has {out.ndim} dimensions; expected a 2-D array")
    return out


def _mesh(V: ArrayLike, F: ArrayLike) -> Tuple[np.ndarray, np.ndarray]:
    V = _matrix("V", V, np.float64, MeshError)
    F = np.asarray(F)
    if F.dtype.kind not in "iu":
        raise MeshError(f"F has dtype {F.dtype}; give integer vertex indices")
    limit = np.iinfo(np.int64).max
    if F.dtype.kind == "u" and F.ndim == 2 and F.size and F.max() > limit:
        # Casting to int64 would wrap the index to a negative one.
        face, corner = (int(i) for i in np.argwhere(F > limit)[0])
        raise MeshError(f"face {face} refers to vertex {F[face, corner]}, beyond any vertex index")
    return V, _matrix("F", F, np.int64, MeshError)


def _mu(mu: ArrayLike) -> np.ndarray:
    out = np.asarray(mu, dtype=np.complex128)
    if out.ndim != 1:
        raise FieldError(f"mu has {out.ndim} dimensions; expected one complex value per face")
    return out


# ---- the call description ---------------------------------------------------------


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def _options(options: Optional[Dict[str, Any]], **flags: Any) -> Dict[str, str]:
    """Solver options as text: the dedicated keyword arguments given (not None), then
    ``options``."""
    out = {name.replace("_", "-"): _text(v) for name, v in flags.items() if v is not None}
    for name, value in (options or {}).items():
        out[str(name)] = _text(value)
    return out


def _goal(
    mu: Optional[ArrayLike], mu_expr: Optional[str], mu_frame: Optional[str], p: Optional[float]
) -> Optional[Dict[str, Any]]:
    """The goal of the description; None (no goal given) leaves it to the solver: the
    extremal map for a solver that computes extremal maps, else the most conformal."""
    if mu is not None and mu_expr is not None:
        raise OptionError("give mu or mu_expr, not both")
    if (mu is not None or mu_expr is not None) and p is not None:
        raise OptionError("p is the exponent of the conformal goal; a prescribed mu has no exponent")
    if mu is not None:
        if mu_frame not in (None, "global", "face"):
            raise OptionError(f"mu_frame={mu_frame!r}: expected 'global' or 'face'")
        return {"kind": "mu", "frame": mu_frame or "global"}
    if mu_expr is not None:
        return {"kind": "mu_expr", "expr": str(mu_expr)}
    if p is None:
        return None
    return {"kind": "conformal", "p": float(p)}


def _pins(pins: Iterable[int]) -> list:
    return [int(i) for i in pins]


def _solve(
    solver: str,
    V: ArrayLike,
    F: ArrayLike,
    spec: Dict[str, Any],
    *,
    boundary_map: Optional[ArrayLike] = None,
    initial: Optional[ArrayLike] = None,
    mu: Optional[ArrayLike] = None,
    target: Optional[Tuple[ArrayLike, ArrayLike]] = None,
    progress: Optional[Progress] = None,
) -> Dict[str, Any]:
    V, F = _mesh(V, F)
    TV, TF = _mesh(*target) if target is not None else (None, None)
    out = _native.solve(
        solver,
        V,
        F,
        json.dumps(spec),
        None if boundary_map is None else _matrix("boundary_map", boundary_map, np.float64, ConstraintError),
        None if initial is None else _matrix("init", initial, np.float64, ConstraintError),
        None if mu is None else _mu(mu),
        TV,
        TF,
        progress,
    )
    out["report"] = json.loads(out["report"])
    return out


def _result(out: Dict[str, Any], info: bool) -> Any:
    return (out["image"], out["report"]) if info else out["image"]


# ---- any registered solver by name --------------------------------------------------


def solve(
    solver: str,
    V: ArrayLike,
    F: ArrayLike,
    *,
    target: str = "plane",
    boundary: Optional[str] = None,
    boundary_map: Optional[ArrayLike] = None,
    mu: Optional[ArrayLike] = None,
    mu_expr: Optional[str] = None,
    mu_frame: Optional[str] = None,
    p: Optional[float] = None,
    pins: Sequence[int] = (),
    initial: Optional[ArrayLike] = None,
    options: Optional[Dict[str, Any]] = None,
    progress: Optional[Progress] = None,
    info: bool = False,
) -> Any:
    """Any registered solver by its name (``beltrami.solvers()`` lists them with what
    each accepts and its options), with the same description of the problem as the named
    calls: ``target`` (``'plane'``, ``'disk'``, ``'annulus'``, ``'sphere'``,
    ``'circle-domain'`` or ``'space'``), the plane's ``boundary`` (``'keep'``,
    ``'free'``, ``'circle'``, ``'square'`` or ``'given'`` with ``boundary_map``), the
    goal (``mu`` per face or ``mu_expr``, else the most conformal map with exponent
    ``p``; with none of the three, the extremal map for a solver that computes extremal
    maps and the most conformal one otherwise), ``pins``, an ``initial`` map, and the
    solver's ``options`` by name. The
    solver refuses, before any work, what it does not accept. Returns the map (``(n, 2)``
    or ``(n, 3)``), with the report when ``info=True``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> UV = beltrami.solve("lscm", V, F, boundary="free")
    >>> bool(np.array_equal(UV, beltrami.lscm(V, F)))
    True
    """
    spec: Dict[str, Any] = {
        "target": target,
        "goal": _goal(mu, mu_expr, mu_frame, p),
        "pins": _pins(pins),
        "options": _options(options),
    }
    if boundary is not None:
        spec["boundary"] = boundary
    out = _solve(str(solver), V, F, spec, boundary_map=boundary_map, initial=initial, mu=mu,
                 progress=progress)
    return _result(out, info)


# ---- initial maps (`beltrami param`) -------------------------------------------------


def _param(solver: str, V: ArrayLike, F: ArrayLike, boundary: str, weights: Optional[str],
           pins: Sequence[int], options: Optional[Dict[str, Any]], info: bool,
           components: Optional[str] = None) -> Any:
    """``beltrami param --solver SOLVER`` onto the plane with ``boundary``."""
    spec = {"target": "plane", "boundary": boundary, "pins": _pins(pins),
            "options": _options(options, weights=weights)}
    if components is not None:
        spec["components"] = components
    return _result(_solve(solver, V, F, spec), info)


@overload
def tutte(
    V: ArrayLike,
    F: ArrayLike,
    *,
    boundary: str = ...,
    weights: Optional[str] = ...,
    pins: Sequence[int] = ...,
    components: Optional[str] = ...,
    options: Optional[Dict[str, Any]] = ...,
    info: Literal[False] = ...,
) -> np.ndarray: ...


@overload
def tutte(
    V: ArrayLike,
    F: ArrayLike,
    *,
    boundary: str = ...,
    weights: Optional[str] = ...,
    pins: Sequence[int] = ...,
    components: Optional[str] = ...,
    options: Optional[Dict[str, Any]] = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, Dict[str, Any]]: ...


def tutte(
    V: ArrayLike,
    F: ArrayLike,
    *,
    boundary: str = "circle",
    weights: Optional[str] = None,
    pins: Sequence[int] = (),
    components: Optional[str] = None,
    options: Optional[Dict[str, Any]] = None,
    info: bool = False,
) -> Any:
    """Tutte's embedding of a disk: every interior vertex at the weighted mean of its
    neighbours (``weights`` ``uniform`` or ``mean-value``), the boundary on the unit
    circle by arc length (``boundary='circle'``) or on the unit square. Bijective for a
    convex boundary (Tutte 1963, Floater 2003). Returns ``UV`` ``(n, 2)``.
    ``beltrami param --solver tutte``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> UV = beltrami.tutte(V, F)
    >>> UV.shape, beltrami.distortion(V, F, UV)["flipped"]
    ((1861, 2), 0)
    """
    return _param("tutte", V, F, boundary, weights, pins, options, info, components)


@overload
def harmonic(
    V: ArrayLike,
    F: ArrayLike,
    *,
    boundary: str = ...,
    weights: Optional[str] = ...,
    pins: Sequence[int] = ...,
    components: Optional[str] = ...,
    options: Optional[Dict[str, Any]] = ...,
    info: Literal[False] = ...,
) -> np.ndarray: ...


@overload
def harmonic(
    V: ArrayLike,
    F: ArrayLike,
    *,
    boundary: str = ...,
    weights: Optional[str] = ...,
    pins: Sequence[int] = ...,
    components: Optional[str] = ...,
    options: Optional[Dict[str, Any]] = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, Dict[str, Any]]: ...


def harmonic(
    V: ArrayLike,
    F: ArrayLike,
    *,
    boundary: str = "circle",
    weights: Optional[str] = None,
    pins: Sequence[int] = (),
    components: Optional[str] = None,
    options: Optional[Dict[str, Any]] = None,
    info: bool = False,
) -> Any:
    """The discrete harmonic map of a disk (cotangent weights, Pinkall-Polthier 1993)
    with the boundary on the unit circle by arc length or on the unit square. Returns
    ``UV`` ``(n, 2)``. ``beltrami param --solver harmonic``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> UV = beltrami.harmonic(V, F)
    >>> round(beltrami.distortion(V, F, UV)["mu_mean"], 2)
    0.01
    """
    return _param("harmonic", V, F, boundary, weights, pins, options, info, components)


@overload
def lscm(
    V: ArrayLike,
    F: ArrayLike,
    b: Optional[ArrayLike] = ...,
    bc: Optional[ArrayLike] = ...,
    *,
    pins: Sequence[int] = ...,
    components: Optional[str] = ...,
    options: Optional[Dict[str, Any]] = ...,
    info: Literal[False] = ...,
) -> np.ndarray: ...


@overload
def lscm(
    V: ArrayLike,
    F: ArrayLike,
    b: Optional[ArrayLike] = ...,
    bc: Optional[ArrayLike] = ...,
    *,
    pins: Sequence[int] = ...,
    components: Optional[str] = ...,
    options: Optional[Dict[str, Any]] = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, Dict[str, Any]]: ...


def lscm(
    V: ArrayLike,
    F: ArrayLike,
    b: Optional[ArrayLike] = None,
    bc: Optional[ArrayLike] = None,
    *,
    pins: Sequence[int] = (),
    components: Optional[str] = None,
    options: Optional[Dict[str, Any]] = None,
    info: bool = False,
) -> Any:
    """Least-squares conformal map (Levy et al. 2002): the minimum of
    ``sum_f A_f |f_zbar|^2`` with a free boundary. Returns ``UV`` ``(n, 2)``.

    Pinned vertices fix the similarity the energy leaves free. ``b`` (rows of ``V``) and
    ``bc`` (``(len(b), 2)`` positions), as libigl's ``lscm(V, F, b, bc)``: each vertex of
    ``b`` goes exactly to its row of ``bc`` (two or more pins). Or ``pins`` (two rows of
    ``V``) sent to 0 and 1; by default two boundary vertices far apart.
    ``beltrami param --solver lscm``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> UV = beltrami.lscm(V, F, [0, 60], [[0.0, 0.0], [2.0, 0.0]])
    >>> UV[[0, 60]].round(12).tolist()
    [[0.0, 0.0], [2.0, 0.0]]
    """
    if b is None and bc is None:
        return _param("lscm", V, F, "free", None, pins, options, info, components)
    if pins:
        raise OptionError("give pins, or b and bc, not both")
    if b is None or bc is None:
        raise ConstraintError("b and bc go together: b the pinned rows of V, bc their (k, 2) positions")
    b = _pins(np.asarray(b).reshape(-1))
    bc = _matrix("bc", bc, np.float64, ConstraintError)
    if bc.shape != (len(b), 2):
        raise ConstraintError(f"bc has shape {bc.shape}; expected ({len(b)}, 2), one position per vertex of b")
    bad = np.flatnonzero(~np.isfinite(bc).all(axis=1))
    if len(bad):
        raise ConstraintError(f"bc row {bad[0]} is not finite: {bc[bad[0]].tolist()}")
    spec = {"target": "plane", "boundary": "free", "pins": b, "pin_positions": bc.tolist(),
            "options": _options(options)}
    if components is not None:
        spec["components"] = components
    return _result(_solve("lscm", V, F, spec), info)


@overload
def sphere_map(
    V: ArrayLike,
    F: ArrayLike,
    *,
    options: Optional[Dict[str, Any]] = ...,
    info: Literal[False] = ...,
) -> np.ndarray: ...


@overload
def sphere_map(
    V: ArrayLike,
    F: ArrayLike,
    *,
    options: Optional[Dict[str, Any]] = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, Dict[str, Any]]: ...


def sphere_map(
    V: ArrayLike,
    F: ArrayLike,
    *,
    options: Optional[Dict[str, Any]] = None,
    info: bool = False,
) -> Any:
    """A conformal map of a closed genus-0 mesh onto the unit sphere, without flipped
    faces: the harmonic map of the punctured mesh, Moebius centring and chart
    corrections (docs/sphere.md). Returns ``W`` ``(n, 3)`` on the unit sphere.
    ``beltrami param --solver sphere``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/spot.obj")
    >>> W = beltrami.sphere_map(V, F)
    >>> bool(np.allclose(np.linalg.norm(W, axis=1), 1)), beltrami.distortion(V, F, W)["flipped"]
    (True, 0)
    """
    spec = {"target": "sphere", "options": _options(options)}
    return _result(_solve("sphere", V, F, spec), info)


# ---- quasiconformal maps (`beltrami qc`) ---------------------------------------------


_QC_DEFAULTS = {"tolerance": "1e-06", "max-iters": "200"}


@overload
def lsqc(
    V: ArrayLike,
    F: ArrayLike,
    *,
    mu: Optional[ArrayLike] = ...,
    mu_expr: Optional[str] = ...,
    mu_frame: Optional[str] = ...,
    target: str = ...,
    boundary: Optional[str] = ...,
    boundary_map: Optional[ArrayLike] = ...,
    pins: Sequence[int] = ...,
    normal_constraint: Optional[float] = ...,
    area_constraint: bool = ...,
    threads: Optional[int] = ...,
    options: Optional[Dict[str, Any]] = ...,
    info: Literal[False] = ...,
) -> np.ndarray: ...


@overload
def lsqc(
    V: ArrayLike,
    F: ArrayLike,
    *,
    mu: Optional[ArrayLike] = ...,
    mu_expr: Optional[str] = ...,
    mu_frame: Optional[str] = ...,
    target: str = ...,
    boundary: Optional[str] = ...,
    boundary_map: Optional[ArrayLike] = ...,
    pins: Sequence[int] = ...,
    normal_constraint: Optional[float] = ...,
    area_constraint: bool = ...,
    threads: Optional[int] = ...,
    options: Optional[Dict[str, Any]] = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, Dict[str, Any]]: ...


def lsqc(
    V: ArrayLike,
    F: ArrayLike,
    *,
    mu: Optional[ArrayLike] = None,
    mu_expr: Optional[str] = None,
    mu_frame: Optional[str] = None,
    target: str = "plane",
    boundary: Optional[str] = None,
    boundary_map: Optional[ArrayLike] = None,
    pins: Sequence[int] = (),
    normal_constraint: Optional[float] = None,
    area_constraint: bool = False,
    threads: Optional[int] = None,
    options: Optional[Dict[str, Any]] = None,
    info: bool = False,
) -> Any:
    """The least-squares quasiconformal map with Beltrami coefficient ``mu`` (one complex
    value per face, in the plane's frame for a planar mesh, ``mu_frame='face'`` for the
    face frames) or ``mu_expr`` (an expression of ``z = x + i y`` at the face
    centroids), or the conformal one when neither is given: the minimum of
    ``sum_f A_f |f_zbar - mu f_z|^2`` (Mastin-Thompson; Gruber-Aulisa 2022, eq. 3.3).

    ``target='plane'`` (default) maps into the plane with ``boundary`` ``'free'``
    (default, with ``pins``), ``'keep'`` (the input's own boundary) or ``'given'``
    (``boundary_map`` ``(n, 2)``); ``target='space'`` maps a surface into R^3 with its
    boundary held at ``boundary_map`` ``(n, 3)`` (the quaternionic map of Gruber-Aulisa
    2022), optionally with the normal constraint of weight ``normal_constraint`` and the
    area constraint (``area_constraint=True``, section 4.2).
    Returns ``UV`` ``(n, 2)`` or ``X`` ``(n, 3)``. ``beltrami qc --solver lsqc``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> flat = V * [1, 1, 0]                    # the hemisphere pressed into the plane
    >>> UV = beltrami.lsqc(flat, F, mu_expr="0.3", boundary="free")
    >>> bool(np.allclose(beltrami.beltrami_coefficient(flat, F, UV), 0.3))
    True
    """
    if target not in ("plane", "space"):
        raise OptionError(f"lsqc maps into the plane or space, not target={target!r}")
    spec = {
        "target": target,
        "boundary": boundary or _lsqc_boundary(target, boundary_map),
        "goal": _goal(mu, mu_expr, mu_frame, None),
        "pins": _pins(pins),
        "normal_constraint": normal_constraint,
        "area_constraint": area_constraint,
        "options": _options(options, threads=threads),
        "defaults": _QC_DEFAULTS,
    }
    out = _solve("lsqc", V, F, spec, boundary_map=boundary_map, mu=mu)
    return _result(out, info)


def _lsqc_boundary(target: str, boundary_map: Optional[ArrayLike]) -> Optional[str]:
    """lsqc's boundary when none is named: free in the plane; into space, held at
    ``boundary_map`` when it is given (else only the pins hold the surface)."""
    if target == "plane":
        return "free"
    return "given" if boundary_map is not None else None


@overload
def beltrami_flow(
    V: ArrayLike,
    F: ArrayLike,
    *,
    mu: Optional[ArrayLike] = ...,
    mu_expr: Optional[str] = ...,
    mu_frame: Optional[str] = ...,
    p: Optional[float] = ...,
    target: str = ...,
    boundary: Optional[str] = ...,
    boundary_map: Optional[ArrayLike] = ...,
    free_radius: bool = ...,
    pins: Sequence[int] = ...,
    tolerance: Optional[float] = ...,
    max_iters: Optional[int] = ...,
    threads: Optional[int] = ...,
    options: Optional[Dict[str, Any]] = ...,
    progress: Optional[Progress] = ...,
    info: Literal[False] = ...,
) -> np.ndarray: ...


@overload
def beltrami_flow(
    V: ArrayLike,
    F: ArrayLike,
    *,
    mu: Optional[ArrayLike] = ...,
    mu_expr: Optional[str] = ...,
    mu_frame: Optional[str] = ...,
    p: Optional[float] = ...,
    target: str = ...,
    boundary: Optional[str] = ...,
    boundary_map: Optional[ArrayLike] = ...,
    free_radius: bool = ...,
    pins: Sequence[int] = ...,
    tolerance: Optional[float] = ...,
    max_iters: Optional[int] = ...,
    threads: Optional[int] = ...,
    options: Optional[Dict[str, Any]] = ...,
    progress: Optional[Progress] = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, Dict[str, Any]]: ...


def beltrami_flow(
    V: ArrayLike,
    F: ArrayLike,
    *,
    mu: Optional[ArrayLike] = None,
    mu_expr: Optional[str] = None,
    mu_frame: Optional[str] = None,
    p: Optional[float] = None,
    target: str = "disk",
    boundary: Optional[str] = None,
    boundary_map: Optional[ArrayLike] = None,
    free_radius: bool = False,
    pins: Sequence[int] = (),
    tolerance: Optional[float] = None,
    max_iters: Optional[int] = None,
    threads: Optional[int] = None,
    options: Optional[Dict[str, Any]] = None,
    progress: Optional[Progress] = None,
    info: bool = False,
) -> Any:
    """The discrete Beltrami flow (Wong-Zhao 2014): the bijective map onto ``target``
    (``'disk'``, ``'annulus'``, ``'sphere'`` or ``'plane'``, the input's own planar
    region) with Beltrami coefficient ``mu``/``mu_expr``, or the most conformal one
    (smallest ``L^p`` norm of mu, ``2 <= p <= 100``) when neither is given. On the sphere
    ``mu_expr`` is in the stereographic coordinate. ``progress(stage, done, total,
    energy)`` is called at every step. Returns ``UV`` ``(n, 2)`` or ``W`` ``(n, 3)`` on
    the sphere. ``beltrami qc --solver beltrami-flow``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> UV = beltrami.beltrami_flow(V, F, target="disk")
    >>> round(float(np.abs(UV @ [1, 1j]).max()), 9), round(beltrami.distortion(V, F, UV)["mu_max"], 2)
    (1.0, 0.02)
    """
    if target not in ("disk", "annulus", "sphere", "plane"):
        raise OptionError(
            f"beltrami_flow maps onto 'disk', 'annulus', 'sphere' or 'plane', not target={target!r}"
        )
    spec = {
        "target": target,
        "boundary": boundary or ("keep" if target == "plane" else None),
        "free_radius": bool(free_radius),
        "goal": _goal(mu, mu_expr, mu_frame, p),
        "pins": _pins(pins),
        "options": _options(options, tolerance=tolerance, max_iters=max_iters, threads=threads),
        "defaults": _QC_DEFAULTS,
    }
    out = _solve("beltrami-flow", V, F, spec, boundary_map=boundary_map, mu=mu, progress=progress)
    return _result(out, info)


def _planar_landmarks(landmarks: Any) -> list:
    """``[(vertex, (x, y))]`` or ``[(vertex, x + iy)]`` as ``[[vertex, x, y]]``."""
    out = []
    for k, pair in enumerate(landmarks):
        try:
            vertex, point = pair
            w = complex(point) if np.ndim(point) == 0 else complex(float(point[0]), float(point[1]))
            out.append([int(vertex), w.real, w.imag])
        except (TypeError, ValueError, IndexError):
            raise ConstraintError(f"landmark {k}: expected (vertex, (x, y)), got {pair!r}") from None
    return out


def _extremal_like(
    solver: str,
    V: ArrayLike,
    F: ArrayLike,
    boundary_map: Optional[ArrayLike],
    init: Union[str, ArrayLike, None],
    flags: Dict[str, Any],
    options: Optional[Dict[str, Any]],
    progress: Optional[Progress],
    info: bool,
    landmarks: Any = None,
) -> Any:
    initial = None
    if init is not None and not isinstance(init, str):
        initial, init = init, None
    if (boundary_map is None) == (landmarks is None):
        raise OptionError(
            "give boundary_map (every boundary vertex placed) or landmarks (four boundary "
            "vertices moved on the unit circle, the rest sliding), one of the two"
        )
    sliding = landmarks is not None
    spec = {
        "target": "disk" if sliding else "plane",
        "boundary": None if sliding else "given",
        "planar_landmarks": _planar_landmarks(landmarks) if sliding else [],
        "goal": {"kind": "extremal"},
        "options": _options(options, init=init, **flags),
        "defaults": _QC_DEFAULTS,
    }
    out = _solve(solver, V, F, spec, boundary_map=boundary_map, initial=initial, progress=progress)
    if not info:
        return out["image"]
    report = out["report"]
    if "qd" in out:
        report["quadratic_differential"] = out["qd"]
    return out["image"], report


@overload
def extremal(
    V: ArrayLike,
    F: ArrayLike,
    boundary_map: Optional[ArrayLike] = ...,
    *,
    landmarks: Any = ...,
    init: Union[str, ArrayLike, None] = ...,
    tolerance: Optional[float] = ...,
    max_iters: Optional[int] = ...,
    threads: Optional[int] = ...,
    options: Optional[Dict[str, Any]] = ...,
    progress: Optional[Progress] = ...,
    info: Literal[False] = ...,
) -> np.ndarray: ...


@overload
def extremal(
    V: ArrayLike,
    F: ArrayLike,
    boundary_map: Optional[ArrayLike] = ...,
    *,
    landmarks: Any = ...,
    init: Union[str, ArrayLike, None] = ...,
    tolerance: Optional[float] = ...,
    max_iters: Optional[int] = ...,
    threads: Optional[int] = ...,
    options: Optional[Dict[str, Any]] = ...,
    progress: Optional[Progress] = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, Dict[str, Any]]: ...


def extremal(
    V: ArrayLike,
    F: ArrayLike,
    boundary_map: Optional[ArrayLike] = None,
    *,
    landmarks: Any = None,
    init: Union[str, ArrayLike, None] = None,
    tolerance: Optional[float] = None,
    max_iters: Optional[int] = None,
    threads: Optional[int] = None,
    options: Optional[Dict[str, Any]] = None,
    progress: Optional[Progress] = None,
    info: bool = False,
) -> Any:
    """The extremal (Teichmueller) map of a disk with the boundary values of
    ``boundary_map`` ``(n, 2)``: the map of smallest largest distortion, with constant
    ``|mu| = k`` and ``mu = k conj(phi)/|phi|`` for a holomorphic quadratic differential
    ``phi`` (Weber-Myles-Zorin 2012, Algorithm 1). ``init``: ``'harmonic'``, ``'tutte'``
    or an ``(n, 2)`` start map (it may fold). Returns ``UV`` ``(n, 2)``; with
    ``info=True`` the report has ``k`` and ``quadratic_differential`` (one complex value
    per face). ``beltrami qc --solver extremal --boundary given``.

    Instead of ``boundary_map``, ``landmarks`` ``[(vertex, (x, y)), ...]`` poses the
    four-point problem: four boundary vertices moved to points of the unit circle, the
    rest of the boundary sliding on it (``beltrami qc --solver extremal --target disk
    --landmarks FILE``).

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> flat = V * [1, 1, 0]                    # the hemisphere pressed into the plane
    >>> stretched = flat[:, :2] * [2.0, 1.0]    # the boundary values of a stretch by 2
    >>> UV = beltrami.extremal(flat, F, stretched)   # the stretch itself, k = 1/3
    >>> bool(np.allclose(UV, stretched)), round(beltrami.distortion(flat, F, UV)["mu_max"], 6)
    (True, 0.333333)
    """
    return _extremal_like(
        "extremal", V, F, boundary_map, init,
        {"tolerance": tolerance, "max_iters": max_iters, "threads": threads},
        options, progress, info, landmarks,
    )


@overload
def qc_iteration(
    V: ArrayLike,
    F: ArrayLike,
    boundary_map: ArrayLike,
    *,
    init: Union[str, ArrayLike, None] = ...,
    tolerance: Optional[float] = ...,
    max_iters: Optional[int] = ...,
    threads: Optional[int] = ...,
    options: Optional[Dict[str, Any]] = ...,
    progress: Optional[Progress] = ...,
    info: Literal[False] = ...,
) -> np.ndarray: ...


@overload
def qc_iteration(
    V: ArrayLike,
    F: ArrayLike,
    boundary_map: ArrayLike,
    *,
    init: Union[str, ArrayLike, None] = ...,
    tolerance: Optional[float] = ...,
    max_iters: Optional[int] = ...,
    threads: Optional[int] = ...,
    options: Optional[Dict[str, Any]] = ...,
    progress: Optional[Progress] = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, Dict[str, Any]]: ...


def qc_iteration(
    V: ArrayLike,
    F: ArrayLike,
    boundary_map: ArrayLike,
    *,
    init: Union[str, ArrayLike, None] = None,
    tolerance: Optional[float] = None,
    max_iters: Optional[int] = None,
    threads: Optional[int] = None,
    options: Optional[Dict[str, Any]] = None,
    progress: Optional[Progress] = None,
    info: bool = False,
) -> Any:
    """The QC iteration towards the Teichmueller map with the boundary values of
    ``boundary_map`` (Lui et al. 2014): alternate the LSQC map of the current mu with
    averaging of mu and projection onto constant modulus. Returns ``UV`` ``(n, 2)``.
    ``beltrami qc --solver qc-iteration --boundary given``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> flat = V * [1, 1, 0]                    # the hemisphere pressed into the plane
    >>> stretched = flat[:, :2] * [2.0, 1.0]    # the boundary values of a stretch by 2
    >>> UV = beltrami.qc_iteration(flat, F, stretched)
    >>> bool(np.allclose(UV, stretched))
    True
    """
    return _extremal_like(
        "qc-iteration", V, F, boundary_map, init,
        {"tolerance": tolerance, "max_iters": max_iters, "threads": threads},
        options, progress, info,
    )


@overload
def circle_domain(
    V: ArrayLike,
    F: ArrayLike,
    *,
    mu: Optional[ArrayLike] = ...,
    mu_expr: Optional[str] = ...,
    mu_frame: Optional[str] = ...,
    outer: Optional[int] = ...,
    tolerance: Optional[float] = ...,
    max_iters: Optional[int] = ...,
    options: Optional[Dict[str, Any]] = ...,
    progress: Optional[Progress] = ...,
    info: Literal[False] = ...,
) -> np.ndarray: ...


@overload
def circle_domain(
    V: ArrayLike,
    F: ArrayLike,
    *,
    mu: Optional[ArrayLike] = ...,
    mu_expr: Optional[str] = ...,
    mu_frame: Optional[str] = ...,
    outer: Optional[int] = ...,
    tolerance: Optional[float] = ...,
    max_iters: Optional[int] = ...,
    options: Optional[Dict[str, Any]] = ...,
    progress: Optional[Progress] = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, Dict[str, Any]]: ...


def circle_domain(
    V: ArrayLike,
    F: ArrayLike,
    *,
    mu: Optional[ArrayLike] = None,
    mu_expr: Optional[str] = None,
    mu_frame: Optional[str] = None,
    outer: Optional[int] = None,
    tolerance: Optional[float] = None,
    max_iters: Optional[int] = None,
    options: Optional[Dict[str, Any]] = None,
    progress: Optional[Progress] = None,
    info: bool = False,
) -> Any:
    """The map of a genus-0 surface with several boundary loops onto a circle domain
    (the unit disk minus disks), conformal or with Beltrami coefficient ``mu``
    (Ho-Lui 2016, Algorithm 2). ``outer`` is the boundary loop sent to the unit circle
    (default: the longest). Returns ``UV`` ``(n, 2)``; with ``info=True`` the report has
    the ``circles`` (loop, centre, radius, deviation). ``beltrami param --solver qcmc``,
    or ``beltrami qc --solver qcmc`` with a mu."""
    prescribed = mu is not None or mu_expr is not None
    spec = {
        "target": "circle-domain",
        "goal": _goal(mu, mu_expr, mu_frame, None),
        "options": _options(
            options,
            tolerance=tolerance,
            max_iters=max_iters,
            outer=None if outer is None else int(outer) + 1,
        ),
        "defaults": _QC_DEFAULTS if prescribed else {},
    }
    return _result(_solve("qcmc", V, F, spec, mu=mu, progress=progress), info)


# ---- registration (`beltrami register`) ----------------------------------------------


def _landmarks(landmarks: Any) -> Optional[str]:
    """The text of a landmarks file from a path, or from pairs: ``(src, tgt)`` moves a
    source vertex onto a target vertex (``v``), ``(src, (x, y, z))`` onto a point
    (``p``)."""
    if landmarks is None:
        return None
    if isinstance(landmarks, (str, os.PathLike)):
        try:
            with open(landmarks, encoding="utf-8") as f:
                return f.read()
        except OSError as e:
            raise MeshFileError(f"landmarks {os.fspath(landmarks)}: {e.strerror}") from None
    lines = []
    for k, pair in enumerate(landmarks):
        try:
            src, goal = pair
            if np.ndim(goal) == 0:
                lines.append(f"v {int(src)} {int(goal)}")
            else:
                x, y, z = (float(c) for c in goal)
                lines.append(f"p {int(src)} {x!r} {y!r} {z!r}")
        except (TypeError, ValueError):
            raise ConstraintError(
                f"landmark {k}: expected (source vertex, target vertex or (x, y, z)), got {pair!r}"
            ) from None
    return "\n".join(lines) + "\n"


def _reversed_landmarks(text: Optional[str]) -> Optional[str]:
    """The landmarks of the registration back: each ``v`` and ``c`` line with its two
    sides exchanged; a ``p`` line has no target vertex to start back from."""
    if text is None:
        return None
    lines = []
    for number, raw in enumerate(text.splitlines(), start=1):
        fields = raw.split("#", 1)[0].split()
        if not fields:
            continue
        if fields[0] in ("v", "c") and len(fields) == 3:
            lines.append(f"{fields[0]} {fields[2]} {fields[1]}")
        else:
            raise ConstraintError(
                f"inverse_consistency: landmarks line {number} is not a `v` or `c` line; "
                "a point has no target vertex to start the registration back from"
            )
    return "\n".join(lines) + "\n"


@overload
def register(
    V: ArrayLike,
    F: ArrayLike,
    TV: ArrayLike,
    TF: ArrayLike,
    *,
    landmarks: Any = ...,
    mu: Optional[ArrayLike] = ...,
    p: Optional[float] = ...,
    features: Optional[Tuple[Any, Any]] = ...,
    tolerance: Optional[float] = ...,
    max_iters: Optional[int] = ...,
    threads: Optional[int] = ...,
    allow_flips: bool = ...,
    allow_missed_landmarks: bool = ...,
    match_shape: bool = ...,
    in_place: bool = ...,
    inverse_consistency: bool = ...,
    options: Optional[Dict[str, Any]] = ...,
    progress: Optional[Progress] = ...,
    info: Literal[False] = ...,
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]: ...


@overload
def register(
    V: ArrayLike,
    F: ArrayLike,
    TV: ArrayLike,
    TF: ArrayLike,
    *,
    landmarks: Any = ...,
    mu: Optional[ArrayLike] = ...,
    p: Optional[float] = ...,
    features: Optional[Tuple[Any, Any]] = ...,
    tolerance: Optional[float] = ...,
    max_iters: Optional[int] = ...,
    threads: Optional[int] = ...,
    allow_flips: bool = ...,
    allow_missed_landmarks: bool = ...,
    match_shape: bool = ...,
    in_place: bool = ...,
    inverse_consistency: bool = ...,
    options: Optional[Dict[str, Any]] = ...,
    progress: Optional[Progress] = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, np.ndarray, np.ndarray, Dict[str, Any]]: ...


def register(
    V: ArrayLike,
    F: ArrayLike,
    TV: ArrayLike,
    TF: ArrayLike,
    *,
    landmarks: Any = None,
    mu: Optional[ArrayLike] = None,
    p: Optional[float] = None,
    features: Optional[Tuple[Any, Any]] = None,
    tolerance: Optional[float] = None,
    max_iters: Optional[int] = None,
    threads: Optional[int] = None,
    allow_flips: bool = False,
    allow_missed_landmarks: bool = False,
    match_shape: bool = False,
    in_place: bool = False,
    inverse_consistency: bool = False,
    options: Optional[Dict[str, Any]] = None,
    progress: Optional[Progress] = None,
    info: bool = False,
) -> Any:
    """A bijective map of the mesh ``V, F`` onto the mesh ``TV, TF`` of the same topology
    (one connected surface of any genus with any number of boundary loops), as conformal
    as the ``landmarks`` allow (smallest
    ``L^p`` norm of mu) or with the Beltrami coefficient ``mu`` (face frames): an initial
    bijection through a common parameter domain, then the Beltrami flow on the target
    (Wong-Zhao 2014). ``landmarks`` is a landmarks file (``v``, ``p`` and ``c`` lines) or
    pairs ``(src, tgt)`` / ``(src, (x, y, z))``; every landmark is exact, or the call
    raises naming the farthest (``allow_missed_landmarks=True`` keeps the map; the
    report's ``landmarks`` lists each distance). ``features=(fs, ft)`` matches a scalar
    field given on both meshes (arrays with one value per row of ``V`` and of ``TV``, or
    ``"mean-curvature"``): the initial map is bent in the common domain until the
    fields agree, the landmarks held (disks and closed genus-0 surfaces).
    ``match_shape=True`` pulls each image towards where the source, placed on the
    target by an affine closest-point fit, lies (a non-rigid ICP that stays a
    bijection; disks and closed genus-0 surfaces; the report's ``shape`` has the mean
    distance before and after). With ``in_place=True`` (with ``match_shape``) the meshes
    lie in one frame and the source near its correspondence (a subject's pial and white
    surfaces): the source is taken where it is, not aligned, and deformed with the
    supple end of the non-rigid ICP's schedule. ``inverse_consistency=True`` also registers ``TV, TF`` onto ``V, F`` (landmark
    pairs reversed, features exchanged) and puts how far each vertex lands from where it
    started, carried there and back, in the report (``info=True``):
    ``inverse_consistency: {mean, max, worst_vertex, relative_mean, relative_max}``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/spot.obj")
    >>> P, face, bary = beltrami.register(V, F, V, F, features=(V[:, 2], V[:, 2]))
    >>> bool(np.abs(P - V).max() < 1e-6)
    True

    Returns ``(P, face, bary)``: the image of every vertex ``(n, 3)``, the row of ``TF``
    it lies in and its barycentric coordinates there (``(n, 3)``, ``(n, 4)`` on quads).
    ``beltrami register`` (with ``--correspondence``)."""
    goal: Optional[Dict[str, Any]]
    if features is not None:
        if mu is not None or p is not None:
            raise OptionError("features start from the least-squares conformal map: give neither mu nor p")
        try:
            fs, ft = features
        except (TypeError, ValueError):
            raise OptionError("features=(source_field, target_field): two fields") from None
        field = lambda x: x if isinstance(x, str) else [float(v) for v in np.asarray(x, dtype=float).ravel()]
        goal = {"kind": "features", "source": field(fs), "target": field(ft)}
    else:
        goal = {"kind": "mu", "frame": "face"} if mu is not None else _goal(None, None, None, p)
    spec: Dict[str, Any] = {
        "target": "mesh",
        "goal": goal,
        "landmarks": _landmarks(landmarks),
        "options": _options(
            options,
            tolerance=tolerance,
            max_iters=max_iters,
            threads=threads,
            allow_flips=True if allow_flips else None,
            allow_missed_landmarks=True if allow_missed_landmarks else None,
            match_shape=True if match_shape else None,
            in_place=True if in_place else None,
        ),
        "defaults": {"tolerance": "1e-05", "max-iters": "100"},
    }
    if mu is not None and p is not None:
        raise OptionError("p is the exponent of the conformal goal; a prescribed mu has no exponent")
    if inverse_consistency:
        if mu is not None:
            raise OptionError("inverse_consistency: a prescribed mu is per source face and has no inverse to run")
        back_spec = dict(spec, landmarks=_reversed_landmarks(spec["landmarks"]))
    out = _solve("register", V, F, spec, mu=mu, target=(TV, TF), progress=progress)
    if inverse_consistency:
        if goal is not None and goal.get("kind") == "features":
            back_spec["goal"] = dict(goal, source=goal["target"], target=goal["source"])
        back = _solve("register", TV, TF, back_spec, target=(V, F), progress=progress)
        start = np.asarray(V, dtype=float)
        there_and_back = np.einsum("ij,ijk->ik", out["bary"], back["image"][np.asarray(TF)[out["face"]]])
        d = np.linalg.norm(there_and_back - start, axis=1)
        size = max(float(np.linalg.norm(start.max(axis=0) - start.min(axis=0))), np.finfo(float).tiny)
        out["report"]["inverse_consistency"] = {
            "mean": float(d.mean()),
            "max": float(d.max()),
            "worst_vertex": int(d.argmax()),
            "relative_mean": float(d.mean()) / size,
            "relative_max": float(d.max()) / size,
        }
    result = (out["image"], out["face"], out["bary"])
    return (*result, out["report"]) if info else result


# ---- measuring -----------------------------------------------------------------------


def beltrami_coefficient(V: ArrayLike, F: ArrayLike, X: ArrayLike) -> np.ndarray:
    """The Beltrami coefficient ``mu = f_zbar / f_z`` of the map with images ``X`` per
    face (rows of ``F``; complex). ``X`` ``(n, 2)`` is a map into the plane, measured in
    the plane's frame when ``V`` lies in z = 0 and in each face's frame otherwise;
    ``X`` ``(n, 3)`` a map into R^3, measured in the face frames. As ``beltrami
    distortion --per-face``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> flat = V * [1, 1, 0]                    # the hemisphere pressed into the plane
    >>> stretched = flat[:, :2] * [2.0, 1.0]    # the boundary values of a stretch by 2
    >>> mu = beltrami.beltrami_coefficient(flat, F, stretched)
    >>> bool(np.allclose(np.abs(mu), 1 / 3))                # (2 - 1) / (2 + 1)
    True
    """
    V, F = _mesh(V, F)
    mu, _frame = _native.beltrami_coefficient(V, F, _matrix("X", X, np.float64, ConstraintError))
    return mu


def distortion(V: ArrayLike, F: ArrayLike, X: ArrayLike) -> Dict[str, Any]:
    """Statistics of ``|mu|`` of the map with images ``X`` (see
    :func:`beltrami_coefficient`): ``faces``, ``flipped``, ``mu_mean``, ``mu_max``,
    ``mu_std``, ``mu_l2`` (area-weighted), ``frame`` and ``flipped_faces`` (rows of
    ``F``). As ``beltrami distortion --json``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> d = beltrami.distortion(V, F, beltrami.tutte(V, F))
    >>> d["flipped"], round(d["mu_mean"], 3)
    (0, 0.135)
    """
    V, F = _mesh(V, F)
    return _native.distortion(V, F, _matrix("X", X, np.float64, ConstraintError))


def mesh_info(V: ArrayLike, F: ArrayLike) -> Dict[str, Any]:
    """Validates the mesh and returns its sizes and topology: ``vertices``, ``faces``,
    ``edges``, ``boundary_loops``, ``components``, ``euler_characteristic``, ``genus``,
    ``topology``. An invalid mesh raises :class:`MeshError` naming the element.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> beltrami.mesh_info(V, F)["topology"]
    'genus 0 and one boundary loop'
    """
    return _native.mesh_info(*_mesh(V, F))


# ---- new meshes ----------------------------------------------------------------------


def _auto_or_count(name: str, value: Union[str, int], least: int, what: str) -> Optional[int]:
    """``None`` for ``"auto"``, else ``value`` as a whole number of at least ``least``."""
    if value == "auto":
        return None
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value >= least:
        return int(value)
    raise OptionError(f"{name}={value!r}: give 'auto' or a whole number of {what} (at least {least})")


def atlas(
    V: ArrayLike,
    F: ArrayLike,
    *,
    cones: Union[str, int] = "auto",
    max_stretch: float = 1.1,
    padding: float = 0.004,
    charts: Union[str, int] = "auto",
) -> Tuple[np.ndarray, np.ndarray, Dict[str, Any]]:
    """A texture atlas of the triangle mesh ``V``, ``F`` (closed or open, any genus, any
    number of pieces): conformal charts with cone singularities (``cones``: ``"auto"``
    places them until the L2 stretch of each chart is at most ``max_stretch``, a number
    places that many per chart), cut open along trees through the cones, split where they
    would overlap, packed into the unit square with ``padding`` (a fraction of the side)
    between charts (docs/atlas.md). ``charts``: ``"auto"`` makes as few charts as the
    stretch limit and the overlap test leave, a number N at least N (the chart with the
    largest share of the squared stretch split until there are). Returns ``(UV, FUV, info)``: the texture coordinates
    ``(k, 2)``, per face the row of ``UV`` of each corner ``(m, 3)`` (``FUV[i, c]`` is the
    coordinate of corner ``F[i, c]``), and the report of ``beltrami atlas --report``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/spot.obj")
    >>> UV, FUV, info = beltrami.atlas(V, F)
    >>> bool(UV.min() >= 0 and UV.max() <= 1) and info["flipped_faces"] == 0
    True
    >>> info["stretch"]["l2"] <= 1.1
    True
    """
    V, F = _mesh(V, F)
    count = _auto_or_count("cones", cones, 0, "cones per chart")
    least = _auto_or_count("charts", charts, 1, "charts")
    UV, FUV, report = _native.atlas(V, F, count, float(max_stretch), float(padding), least)
    return UV, FUV, json.loads(report)


@overload
def remesh(
    V: ArrayLike,
    F: ArrayLike,
    *,
    edge_length: Optional[float] = ...,
    vertices: Optional[int] = ...,
    param: str = ...,
    min_angle: float = ...,
    size_field: str = ...,
    max_vertices: int = ...,
    feature_tolerance: float = ...,
    components: Optional[str] = ...,
    info: Literal[False] = ...,
) -> Tuple[np.ndarray, np.ndarray]: ...


@overload
def remesh(
    V: ArrayLike,
    F: ArrayLike,
    *,
    edge_length: Optional[float] = ...,
    vertices: Optional[int] = ...,
    param: str = ...,
    min_angle: float = ...,
    size_field: str = ...,
    max_vertices: int = ...,
    feature_tolerance: float = ...,
    components: Optional[str] = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, np.ndarray, Dict[str, Any]]: ...


def remesh(
    V: ArrayLike,
    F: ArrayLike,
    *,
    edge_length: Optional[float] = None,
    vertices: Optional[int] = None,
    param: str = "auto",
    min_angle: float = 30.0,
    size_field: str = "uniform",
    max_vertices: int = 5_000_000,
    feature_tolerance: float = 0.2,
    components: Optional[str] = None,
    info: bool = False,
) -> Any:
    """A new triangle mesh of the surface with the asked ``edge_length`` (or about
    ``vertices`` vertices): parameterize (``param``: ``auto``, a solver, or ``sphere``
    for a closed genus-0 surface in two charts), triangulate the parameter domain by
    constrained Delaunay refinement with angles of at least ``min_angle`` degrees, lift
    back (docs/remesh.md); input vertices farther than ``feature_tolerance`` times the
    edge length from the result are inserted (``inf``: none). A mesh in several
    connected pieces needs ``components``: ``"each"`` remeshes every piece on its own
    (``vertices`` shared out by area) and joins the results in the order of each
    piece's first face, ``"largest"`` remeshes only the largest. Returns ``(V2, F2)``.
    ``beltrami remesh``.

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> V2, F2 = beltrami.remesh(V, F, vertices=500)
    >>> abs(len(V2) - 500) < 50
    True
    """
    V, F = _mesh(V, F)
    for name, value in (("vertices", vertices), ("max_vertices", max_vertices)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1):
            raise OptionError(f"{name}={value!r}: give a whole number of vertices, at least 1")
    V2, F2, report = _native.remesh(
        V,
        F,
        edge_length,
        vertices,
        param,
        float(min_angle),
        size_field,
        int(max_vertices),
        float(feature_tolerance),
        components,
    )
    return (V2, F2, json.loads(report)) if info else (V2, F2)


@overload
def remesh_in_place(
    V: ArrayLike,
    F: ArrayLike,
    *,
    reference: str = ...,
    constraint: str = ...,
    max_iters: int = ...,
    tolerance: float = ...,
    feature_angle: float = ...,
    project: bool = ...,
    allow_flips: bool = ...,
    info: Literal[False] = ...,
) -> np.ndarray: ...


@overload
def remesh_in_place(
    V: ArrayLike,
    F: ArrayLike,
    *,
    reference: str = ...,
    constraint: str = ...,
    max_iters: int = ...,
    tolerance: float = ...,
    feature_angle: float = ...,
    project: bool = ...,
    allow_flips: bool = ...,
    info: Literal[True],
) -> Tuple[np.ndarray, Dict[str, Any]]: ...


def remesh_in_place(
    V: ArrayLike,
    F: ArrayLike,
    *,
    reference: str = "optimized",
    constraint: str = "normal",
    max_iters: int = 10,
    tolerance: float = 1e-4,
    feature_angle: float = 60.0,
    project: bool = True,
    allow_flips: bool = False,
    info: bool = False,
) -> Any:
    """The same vertices and faces moved along the surface towards reference angles
    (``reference``: ``optimized``, Gruber-Aulisa 2022 Algorithm 5, or ``equiangular``) by
    the QC iteration into R^3 with the ``constraint`` ``normal`` or ``area``, vertices on
    creases sharper than ``feature_angle`` degrees held, moved vertices projected onto
    the input (docs/remesh-in-place.md). Returns ``V2`` ``(n, 3)`` (the faces are ``F``).
    ``beltrami remesh --method qc-angles``."""
    V, F = _mesh(V, F)
    V2, report = _native.remesh_in_place(
        V, F, reference, constraint, int(max_iters), float(tolerance), float(feature_angle),
        bool(project), bool(allow_flips),
    )
    return (V2, json.loads(report)) if info else V2


@overload
def cut_to_disk(
    V: ArrayLike,
    F: ArrayLike,
    *,
    info: Literal[False] = ...,
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]: ...


@overload
def cut_to_disk(
    V: ArrayLike,
    F: ArrayLike,
    *,
    info: Literal[True],
) -> Tuple[np.ndarray, np.ndarray, np.ndarray, Dict[str, Any]]: ...


def cut_to_disk(V: ArrayLike, F: ArrayLike, *, info: bool = False) -> Any:
    """The surface (genus >= 1, or several boundary loops) cut into a topological disk
    along a greedy shortest system of loops. Returns ``(V2, F2, original)``: face ``i``
    of ``F2`` is face ``i`` of ``F``, and ``original[j]`` is the row of ``V`` that
    cut-mesh vertex ``j`` copies. ``beltrami cut``."""
    V2, F2, original, report = _native.cut_to_disk(*_mesh(V, F))
    return (V2, F2, original, json.loads(report)) if info else (V2, F2, original)


def repair(
    V: ArrayLike,
    F: ArrayLike,
    *,
    merge_vertices: bool = True,
    drop_degenerate_faces: bool = True,
    drop_duplicate_faces: bool = True,
) -> Tuple[np.ndarray, np.ndarray, dict]:
    """The mesh mended as ``beltrami info --repair`` mends a file: vertices at exactly
    the same position merged into the first, faces with a repeated vertex or zero area
    dropped, faces with the vertex set of an earlier face dropped, then every face
    oriented consistently with its component. Vertices no kept face uses are left out.

    Returns ``(V2, F2, info)``. ``info["vertex_index"]`` has one entry per row of ``V``:
    its row in ``V2`` (-1 when left out); ``info["face_index"]`` has one entry per row of
    ``F2``: its row in ``F``. The other keys list what changed by input row:
    ``merged_vertices`` (pairs ``(merged, kept)``), ``dropped_degenerate_faces``,
    ``dropped_duplicate_faces``, ``unreferenced_vertices``, ``faces_reoriented``.

    >>> import numpy as np, beltrami
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    >>> F = np.array([[0, 1, 2], [3, 4, 5]])            # a square as a triangle soup
    >>> V2, F2, info = beltrami.repair(V, F)
    >>> V2.shape, F2.tolist(), info["vertex_index"].tolist()
    ((4, 3), [[0, 1, 2], [0, 2, 3]], [0, 1, 2, 0, 2, 3])
    """
    V2, F2, vertex_index, face_index, report = _native.repair(
        *_mesh(V, F), merge_vertices, drop_degenerate_faces, drop_duplicate_faces
    )
    info = json.loads(report)
    info["vertex_index"] = vertex_index
    info["face_index"] = face_index
    return V2, F2, info


def weld(V: ArrayLike, F: ArrayLike) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mesh with vertices at exactly the same position merged (a triangle soup, an
    STL file's corners): ``repair`` without dropping faces. Returns ``(V2, F2, index)``,
    ``index[i]`` the row of ``V2`` of row ``i`` of ``V`` (-1 when no face uses it). A
    face whose corners weld together is a ``MeshError`` naming it: ``repair`` drops such
    faces.

    >>> import numpy as np, beltrami
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    >>> V2, F2, index = beltrami.weld(V, [[0, 1, 2], [3, 4, 5]])
    >>> len(V2), index.tolist()
    (4, [0, 1, 2, 1, 3, 2])
    """
    V2, F2, info = repair(V, F, drop_degenerate_faces=False, drop_duplicate_faces=False)
    return V2, F2, info["vertex_index"]


def show(
    V: ArrayLike,
    F: ArrayLike,
    *,
    uv: Optional[ArrayLike] = None,
    mu: Optional[ArrayLike] = None,
    name: str = "mesh",
) -> None:
    """Shows the mesh in polyscope's window (``pip install "beltrami[view]"``): the
    texture coordinates ``uv`` ``(n, 2)`` as a checkered parameterization and ``|mu|``
    (one value per face, complex or real) in viridis over ``[0, 1]``. Without a display,
    ``beltrami view`` writes a self-contained HTML page instead.

    >>> import beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> uv = beltrami.lscm(V, F)
    >>> beltrami.show(V, F, uv=uv, mu=beltrami.beltrami_coefficient(V, F, uv))  # doctest: +SKIP
    """
    try:
        import polyscope as ps
    except ImportError:
        raise UnsupportedError(
            'beltrami.show draws with polyscope, which is not installed: pip install "beltrami[view]"'
            " (or polyscope); `beltrami view` writes an HTML page without it"
        ) from None
    V, F = _mesh(V, F)
    ps.init()
    surface = ps.register_surface_mesh(name, V, F)
    if uv is not None:
        uv = _matrix("uv", uv, np.float64, ConstraintError)
        if uv.shape != (len(V), 2):
            raise ConstraintError(f"uv has shape {uv.shape}; expected ({len(V)}, 2)")
        surface.add_parameterization_quantity("uv", uv, defined_on="vertices", enabled=True)
    if mu is not None:
        modulus = np.abs(np.asarray(mu))
        if modulus.shape != (len(F),):
            raise FieldError(f"mu has shape {modulus.shape}; expected ({len(F)},), one value per face")
        surface.add_scalar_quantity(
            "|mu|", modulus, defined_on="faces", cmap="viridis", vminmax=(0.0, 1.0), enabled=uv is None
        )
    ps.show()


# ---- files and the catalog -----------------------------------------------------------


@overload
def read_mesh(path: Union[str, "os.PathLike[str]"], *, uv: Literal[False] = ...) -> Tuple[np.ndarray, np.ndarray]: ...


@overload
def read_mesh(
    path: Union[str, "os.PathLike[str]"], *, uv: Literal[True]
) -> Tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]: ...


def read_mesh(path: Union[str, "os.PathLike[str]"], *, uv: bool = False) -> Any:
    """Reads an OBJ, PLY, STL, OFF, glTF or GLB mesh: ``(V, F)``, or ``(V, F, UV)``
    with ``uv=True`` (``UV`` ``(n, 2)`` when the file has one texture coordinate per
    vertex, else None). The mesh is validated as the command line validates its input;
    an STL file's corners are welded into vertices by exact position.

    >>> import beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> V.shape, F.shape
    ((1861, 3), (3600, 3))
    """
    V, F, UV = _native.read_mesh(os.fspath(path))
    return (V, F, UV) if uv else (V, F)


def write_mesh(
    path: Union[str, "os.PathLike[str]"], V: ArrayLike, F: ArrayLike, uv: Optional[ArrayLike] = None
) -> None:
    """Writes the mesh (OBJ, PLY, STL, OFF, glTF or GLB by extension), with texture
    coordinates ``uv`` ``(n, 2)`` when given (STL holds none: an error); atomically (a
    complete file or none).

    >>> import numpy as np, beltrami
    >>> V, F = beltrami.read_mesh("meshes/disk_hemisphere.obj")
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "uv.ply")
    >>> beltrami.write_mesh(path, V, F, uv=beltrami.tutte(V, F))
    >>> beltrami.read_mesh(path, uv=True)[2].shape
    (1861, 2)
    """
    V, F = _mesh(V, F)
    UV = None if uv is None else _matrix("uv", uv, np.float64, ConstraintError)
    _native.write_mesh(os.fspath(path), V, F, UV)


def solvers() -> list:
    """Every registered solver with what it accepts and its options (types, defaults,
    ranges), as ``beltrami solvers --json``.

    >>> import beltrami
    >>> lscm = next(s for s in beltrami.solvers() if s["name"] == "lscm")
    >>> lscm["accepts"]["targets"]
    ['plane-free']
    """
    return json.loads(_native.solvers())
