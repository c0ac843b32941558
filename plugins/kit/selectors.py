"""Boundary and region selectors written in YAML, without code.

The shell benchmarks (thesis L1330–1450, Paper 1 §4) impose clamped, simply supported
(rigid diaphragm) and symmetry conditions on parts of the boundary curves, and loads on
points or regions; the boundary conditions are imposed with Lagrange multipliers on the
boundary curves (Paper 1 §4.1.2, Appendix D). A :class:`Selector` names such a part by
geometric criteria, all AND-ed::

    clamped: {plane: [1, 0, 0, 5.0]}                 # the edge x = 5
    free_edge: {expression: "abs(theta) > 0.69"}     # points by a formula
    hole: {nearest_curve: [0, 0, 10]}                 # the boundary curve nearest to a point
    crack: {polyline: [[0.3, 0.5, 0], [0.7, 0.5, 0]], on_boundary: false}  # near a curve
    load: {box: [-0.1, -0.1, -1, 0.1, 0.1, 1], on_boundary: false}

Expressions are checked against a whitelist and evaluated on read-only copies of the
coordinates by :mod:`.expression`.
"""
from __future__ import annotations

import numpy as np

from pointatlas.errors import ConfigError, InputError

from .expression import ALLOWED, FUNCTIONS, VARIABLES, evaluate_expression  # noqa: F401
from .selector_spec import Selector, describe  # noqa: F401  (re-exported)


def _vector(selector: Selector, field: str, size: int) -> np.ndarray:
    value = getattr(selector, field)
    try:
        arr = np.asarray(value, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        arr = np.empty(0)
    if arr.size != size or not np.isfinite(arr).all():
        raise ConfigError(f"{describe(selector)}: {field}={value!r} must be {size} finite numbers. "
                          + {"plane": "Give [nx, ny, nz, d] for the plane n·x = d.",
                             "box": "Give [xmin, ymin, zmin, xmax, ymax, zmax].",
                             "nearest_curve": "Give a point [x, y, z] near the curve."}[field])
    return arr


#: the criteria a selector can combine
CRITERIA = ("plane", "box", "expression", "nearest_curve", "polyline")


def polyline_vertices(selector: Selector) -> np.ndarray:
    """(k, 3) vertices of ``selector.polyline`` (k ≥ 2 finite points), or ConfigError."""
    try:
        V = np.asarray(selector.polyline, dtype=np.float64)
    except (TypeError, ValueError):
        V = np.empty((0,))
    if V.ndim != 2 or V.shape[0] < 2 or V.shape[1] != 3 or not np.isfinite(V).all():
        raise ConfigError(f"{describe(selector)}: polyline={selector.polyline!r} must be two or "
                          "more points [x, y, z], e.g. [[0.3, 0.5, 0], [0.7, 0.5, 0]].")
    return V


def distance_to_polyline(X: np.ndarray, V: np.ndarray) -> np.ndarray:
    """(n,) Euclidean distance of points X (n, 3) to the polyline through vertices V (k, 3)."""
    d = np.full(len(X), np.inf)
    for a, b in zip(V[:-1], V[1:]):
        e = b - a
        L2 = float(e @ e)
        t = np.clip(((X - a) @ e) / L2, 0.0, 1.0) if L2 > 0 else np.zeros(len(X))
        d = np.minimum(d, np.linalg.norm(X - a - t[:, None] * e, axis=1))
    return d


def default_tolerance(points: np.ndarray) -> float:
    """0.25 × median nearest-neighbour distance of the points (length units)."""
    from scipy.spatial import cKDTree

    return 0.25 * float(np.median(cKDTree(points).query(points, k=2)[0][:, 1]))


def _bbox(P: np.ndarray) -> str:
    if len(P) == 0:
        return "(none)"
    return f"[{', '.join(f'{v:.6g}' for v in P.min(axis=0))}] to " \
           f"[{', '.join(f'{v:.6g}' for v in P.max(axis=0))}]"


def select(selector: Selector, points, boundary_mask, curves) -> np.ndarray:
    """Sorted indices of the points satisfying every criterion of ``selector``.

    ``boundary_mask`` (N,) flags boundary points and ``curves`` are the boundary curves
    (index arrays), from :mod:`pointatlas_atlas.boundary`. Raises :class:`ConfigError` for a
    selector without criterion or with malformed criteria, :class:`InputError` when nothing
    is selected (naming the bounding boxes of the points and of the boundary points).
    """
    if not isinstance(selector, Selector):
        raise ConfigError(f"expected a Selector, got {type(selector).__name__}; build one with "
                          "Selector(plane=..., box=..., expression=..., nearest_curve=...).")
    X = np.asarray(points, dtype=np.float64)
    bmask = np.asarray(boundary_mask, dtype=bool)
    if all(getattr(selector, f) is None for f in CRITERIA):
        raise ConfigError(f"{describe(selector)} has no criterion: give at least one of "
                          f"{', '.join(CRITERIA)}.")
    tol = selector.tol
    if tol is None:
        tol = default_tolerance(X)
    elif not (isinstance(tol, (int, float)) and np.isfinite(tol) and tol >= 0):
        raise ConfigError(f"{describe(selector)}: tol={tol!r} must be a length >= 0 or None "
                          "(0.25 × median point spacing).")
    keep = bmask.copy() if selector.on_boundary else np.ones(len(X), dtype=bool)
    if selector.plane is not None:
        p = _vector(selector, "plane", 4)
        norm = np.linalg.norm(p[:3])
        if norm == 0:
            raise ConfigError(f"{describe(selector)}: the plane normal is zero; give [nx, ny, nz, d].")
        keep &= np.abs(X @ p[:3] - p[3]) <= tol * norm
    if selector.box is not None:
        b = _vector(selector, "box", 6)
        keep &= np.all((X >= b[:3] - tol) & (X <= b[3:] + tol), axis=1)
    if selector.expression is not None:
        keep &= evaluate_expression(selector.expression, X)
    if selector.nearest_curve is not None:
        q = _vector(selector, "nearest_curve", 3)
        if not curves:
            raise InputError(f"{describe(selector)}: the surface has no boundary curve. "
                             "Use plane, box or expression, or check the boundary detection.")
        dist = [np.linalg.norm(X[np.asarray(c)] - q, axis=1).min() for c in curves]
        on_curve = np.zeros(len(X), dtype=bool)
        on_curve[np.asarray(curves[int(np.argmin(dist))])] = True
        keep &= on_curve
    if selector.polyline is not None:
        keep &= distance_to_polyline(X, polyline_vertices(selector)) <= tol
    chosen = np.flatnonzero(keep)
    if chosen.size == 0:
        raise InputError(
            f"{describe(selector)} selects no point (tol={tol:.3g}). Points span {_bbox(X)}; "
            f"boundary points span {_bbox(X[bmask])}. Check the coordinates against these boxes, "
            "enlarge tol, or set on_boundary: false to select interior points.")
    return chosen
