"""Boundary and region selectors written in YAML, without code.

The shell benchmarks (thesis L1330–1450, Paper 1 §4) impose clamped, simply supported
(rigid diaphragm) and symmetry conditions on parts of the boundary curves, and loads on
points or regions; the boundary conditions are imposed with Lagrange multipliers on the
boundary curves (Paper 1 §4.1.2, Appendix D). A :class:`Selector` names such a part by
geometric criteria, all AND-ed::

    clamped: {plane: [1, 0, 0, 5.0]}                 # the edge x = 5
    free_edge: {expression: "abs(theta) > 0.69"}     # points by a formula
    hole: {nearest_curve: [0, 0, 10]}                 # the boundary curve nearest to a point
    load: {box: [-0.1, -0.1, -1, 0.1, 0.1, 1], on_boundary: false}

Expressions are parsed with :mod:`ast` and evaluated on numpy arrays from a whitelist only.
"""
from __future__ import annotations

import ast
import operator

import numpy as np

from pointatlas.errors import ConfigError, InputError

from .selector_spec import Selector, describe  # noqa: F401  (re-exported)

#: Variables of an expression: coordinates, distances to the origin and to the z axis, the
#: polar angle from +z (theta) and the azimuth about z (phi), radians.
VARIABLES = ("x", "y", "z", "r", "rho", "theta", "phi")
FUNCTIONS = {"abs": np.abs, "sqrt": np.sqrt, "sin": np.sin, "cos": np.cos, "tan": np.tan,
             "arcsin": np.arcsin, "arccos": np.arccos, "arctan": np.arctan,
             "arctan2": np.arctan2, "exp": np.exp, "log": np.log, "hypot": np.hypot,
             "minimum": np.minimum, "maximum": np.maximum, "isclose": np.isclose}
CONSTANTS = {"pi": np.pi, "e": np.e}
_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
           ast.Div: operator.truediv, ast.Pow: operator.pow, ast.Mod: operator.mod}
_UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos}
_COMPARE = {ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt,
            ast.GtE: operator.ge, ast.Eq: operator.eq, ast.NotEq: operator.ne}
ALLOWED = ("numbers; variables " + ", ".join(VARIABLES) + "; constants "
           + ", ".join(CONSTANTS) + "; functions " + ", ".join(FUNCTIONS)
           + "; operators + - * / ** %, comparisons (chains allowed), and, or, not")


def _reject(token: str, expression: str):
    raise ConfigError(f"expression {expression!r}: {token} is not allowed. Allowed: {ALLOWED}.")


def _evaluate(node, env: dict, expression: str):
    """Evaluate a whitelisted expression tree on arrays."""
    if isinstance(node, ast.Expression):
        return _evaluate(node.body, env, expression)
    if isinstance(node, ast.Constant):
        if isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
            return np.float64(node.value)  # float arithmetic: 9**9**9 overflows to inf, fast
        _reject(f"the constant {node.value!r}", expression)
    if isinstance(node, ast.Name):
        if node.id in env:
            return env[node.id]
        if node.id in CONSTANTS:
            return CONSTANTS[node.id]
        _reject(f"the name {node.id!r}", expression)
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        return _BINARY[type(node.op)](_evaluate(node.left, env, expression),
                                      _evaluate(node.right, env, expression))
    if isinstance(node, ast.UnaryOp) and type(node.op) in _UNARY:
        return _UNARY[type(node.op)](_evaluate(node.operand, env, expression))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
        return np.logical_not(_evaluate(node.operand, env, expression))
    if isinstance(node, ast.BoolOp):
        combine = np.logical_and if isinstance(node.op, ast.And) else np.logical_or
        values = [_evaluate(v, env, expression) for v in node.values]
        out = values[0]
        for v in values[1:]:
            out = combine(out, v)
        return out
    if isinstance(node, ast.Compare) and all(type(op) in _COMPARE for op in node.ops):
        left = _evaluate(node.left, env, expression)
        out = True
        for op, right_node in zip(node.ops, node.comparators):
            right = _evaluate(right_node, env, expression)
            out = np.logical_and(out, _COMPARE[type(op)](left, right))
            left = right
        return out
    if isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS:
            _reject(f"the function {ast.unparse(node.func)!r}", expression)
        if node.keywords:
            _reject("keyword arguments", expression)
        return FUNCTIONS[node.func.id](*(_evaluate(a, env, expression) for a in node.args))
    _reject(f"{ast.unparse(node)!r} ({type(node).__name__})", expression)


def evaluate_expression(expression: str, points: np.ndarray) -> np.ndarray:
    """(N,) bool: the whitelisted boolean ``expression`` evaluated at ``points`` (N, 3)."""
    try:
        tree = ast.parse(expression.strip(), mode="eval")
    except SyntaxError as err:
        raise ConfigError(f"expression {expression!r} is not valid Python syntax ({err.msg}). "
                          "Write e.g. \"abs(x - 5) < 1e-6 and y > 0\".") from None
    x, y, z = points.T
    rho = np.hypot(x, y)
    r = np.sqrt(rho**2 + z**2)
    env = {"x": x, "y": y, "z": z, "r": r, "rho": rho, "theta": np.arctan2(rho, z),
           "phi": np.arctan2(y, x)}
    with np.errstate(all="ignore"):
        value = _evaluate(tree, env, expression)
    value = np.broadcast_to(np.asarray(value), (len(points),))
    if value.dtype != bool:
        raise ConfigError(f"expression {expression!r} gives {value.dtype} values, not true/false. "
                          "Compare something, e.g. \"abs(x - 5) < 1e-6\".")
    return value


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
    if all(getattr(selector, f) is None for f in ("plane", "box", "expression", "nearest_curve")):
        raise ConfigError(f"{describe(selector)} has no criterion: give at least one of plane, "
                          "box, expression, nearest_curve.")
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
        keep &= evaluate_expression(str(selector.expression), X)
    if selector.nearest_curve is not None:
        q = _vector(selector, "nearest_curve", 3)
        if not curves:
            raise InputError(f"{describe(selector)}: the surface has no boundary curve. "
                             "Use plane, box or expression, or check the boundary detection.")
        dist = [np.linalg.norm(X[np.asarray(c)] - q, axis=1).min() for c in curves]
        on_curve = np.zeros(len(X), dtype=bool)
        on_curve[np.asarray(curves[int(np.argmin(dist))])] = True
        keep &= on_curve
    chosen = np.flatnonzero(keep)
    if chosen.size == 0:
        raise InputError(
            f"{describe(selector)} selects no point (tol={tol:.3g}). Points span {_bbox(X)}; "
            f"boundary points span {_bbox(X[bmask])}. Check the coordinates against these boxes, "
            "enlarge tol, or set on_boundary: false to select interior points.")
    return chosen
