"""Safe evaluation of a selector's boolean ``expression`` on the coordinates of the points.

An expression such as ``"abs(x - 5) < 1e-6 and y > 0"`` is parsed with :mod:`ast`, checked
against a whitelist *before* anything is evaluated, then evaluated on numpy arrays:

* variables x, y, z (length), r = |x| and rho = √(x² + y²) (length), theta = the polar angle
  from +z and phi = the azimuth about z (radians, ``arctan2``); constants pi and e; finite
  numbers;
* the functions of :data:`FUNCTIONS`, each with exactly its number of positional arguments
  (no keyword or starred arguments: a numpy ufunc takes its output array positionally, so
  ``sin(y, y)`` would otherwise write sin(y) into y);
* operators + - * / ** %, unary - + not, comparisons (chains allowed), and, or.

Every variable is a read-only copy, so no expression can change the points. An expression
is at most :data:`MAX_LENGTH` characters long and nested at most :data:`MAX_DEPTH` levels
deep (brackets, or operators and calls inside one another); longer or deeper ones are
refused with a :class:`ConfigError` before Python's parser could exhaust its stack. The
result must be one true/false value per point.
"""
from __future__ import annotations

import ast
import operator

import numpy as np

from pointatlas.errors import ConfigError

#: Variables of an expression (see the module doc for their meaning and units).
VARIABLES = ("x", "y", "z", "r", "rho", "theta", "phi")
#: name -> (numpy function, its positional parameters, an example call). isclose(a, b) is
#: |a − b| ≤ 1e-8 + 1e-5·|b| (numpy's default tolerances); write abs(a - b) < tol for another.
FUNCTIONS = {
    "abs": (np.abs, ("x",), "abs(x - 5) < 1e-6"),
    "sqrt": (np.sqrt, ("x",), "sqrt(x**2 + y**2) < 1"),
    "sin": (np.sin, ("x",), "sin(theta) > 0.5"),
    "cos": (np.cos, ("x",), "cos(phi) > 0"),
    "tan": (np.tan, ("x",), "tan(theta) < 1"),
    "arcsin": (np.arcsin, ("x",), "arcsin(z / r) > 0.1"),
    "arccos": (np.arccos, ("x",), "arccos(z / r) < 0.5"),
    "arctan": (np.arctan, ("x",), "arctan(y / x) > 0"),
    "arctan2": (np.arctan2, ("y", "x"), "arctan2(y, x) < pi/2"),
    "exp": (np.exp, ("x",), "exp(-r) > 0.5"),
    "log": (np.log, ("x",), "log(r) < 1"),
    "hypot": (np.hypot, ("a", "b"), "hypot(x, y) < 1"),
    "minimum": (np.minimum, ("a", "b"), "minimum(x, y) > 0"),
    "maximum": (np.maximum, ("a", "b"), "maximum(x, y) < 1"),
    "isclose": (np.isclose, ("a", "b"), "isclose(x, 5)"),
}
CONSTANTS = {"pi": np.float64(np.pi), "e": np.float64(np.e)}  # numpy floats: 1/0 is inf
#: Longest expression accepted (characters) and deepest nesting (levels).
MAX_LENGTH = 1000
MAX_DEPTH = 50

_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
           ast.Div: operator.truediv, ast.Pow: operator.pow, ast.Mod: operator.mod}
_UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos, ast.Not: np.logical_not}
_COMPARE = {ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt,
            ast.GtE: operator.ge, ast.Eq: operator.eq, ast.NotEq: operator.ne}
ALLOWED = ("numbers; variables " + ", ".join(VARIABLES) + "; constants "
           + ", ".join(CONSTANTS) + "; functions "
           + ", ".join(f"{name}({', '.join(params)})" for name, (_, params, _) in FUNCTIONS.items())
           + "; operators + - * / ** %, comparisons (chains allowed), and, or, not")


def _shown(expression: str) -> str:
    """The expression quoted for a message, cut to 60 characters (one line: repr escapes)."""
    return repr(expression if len(expression) <= 60 else expression[:57] + "...")


def _fail(expression: str, problem: str, fix: str):
    raise ConfigError(f"selector expression {_shown(expression)}: {problem}. Fix: {fix}")


def _reject(token: str, expression: str):
    _fail(expression, f"{token} is not allowed", f"use only these. Allowed: {ALLOWED}.")


def _bracket_depth(text: str) -> int:
    depth = deepest = 0
    for ch in text:
        if ch in "([{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in ")]}":
            depth -= 1
    return deepest


def _source(node, expression: str) -> str:
    """The text of ``node`` in ``expression`` (not :func:`ast.unparse`, which recurses)."""
    return _shown(ast.get_source_segment(expression, node) or type(node).__name__)


def _check_call(node: ast.Call, expression: str) -> None:
    if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS:
        _reject(f"calling {_source(node.func, expression)}", expression)
    name = node.func.id
    _, params, example = FUNCTIONS[name]
    takes = (f"{name} takes {len(params)} argument{'s' if len(params) > 1 else ''} "
             f"({', '.join(params)})")
    fix = f"write {name}({', '.join(params)}), e.g. {example!r}"
    if node.keywords:
        kw = ", ".join(f"{k.arg}=..." if k.arg else "**..." for k in node.keywords)
        _fail(expression, f"{takes} and no keyword arguments, got {kw}", fix + ".")
    if any(isinstance(a, ast.Starred) for a in node.args):
        _fail(expression, f"{takes} and no starred (*) arguments", fix + ".")
    if len(node.args) != len(params):
        extra = (" (numpy would take the extra one as an output array and overwrite it)"
                 if len(node.args) > len(params) else "")
        _fail(expression, f"{takes}, got {len(node.args)}{extra}",
              fix + ("; for another tolerance write abs(a - b) < tol." if name == "isclose"
                     else "."))


def _children(node, expression: str) -> list:
    """The sub-expressions of a whitelisted node; anything else is refused."""
    if isinstance(node, ast.Constant):
        value = node.value
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            _reject(f"the constant {value!r}", expression)
        try:
            ok = np.isfinite(float(value))
        except OverflowError:
            ok = False
        if not ok:
            _fail(expression, f"the number {_shown(str(value))} is not a finite float "
                  "(|value| < 1.8e308)", "write a smaller number.")
        return []
    if isinstance(node, ast.Name):
        if node.id in FUNCTIONS:
            _fail(expression, f"{node.id} is a function, not a value",
                  f"call it, e.g. {FUNCTIONS[node.id][2]!r}.")
        if node.id not in VARIABLES and node.id not in CONSTANTS:
            _reject(f"the name {node.id!r}", expression)
        return []
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        return [node.left, node.right]
    if isinstance(node, ast.UnaryOp) and type(node.op) in _UNARY:
        return [node.operand]
    if isinstance(node, ast.BoolOp):
        return list(node.values)
    if isinstance(node, ast.Compare) and all(type(op) in _COMPARE for op in node.ops):
        return [node.left, *node.comparators]
    if isinstance(node, ast.Call):
        _check_call(node, expression)
        return list(node.args)
    op = getattr(node, "op", None) or next(iter(getattr(node, "ops", [])), None)
    if op is not None:  # an operator outside the whitelist (e.g. @, ~, <<, in, is)
        bad = [o for o in getattr(node, "ops", [op]) if type(o) not in _COMPARE] or [op]
        _reject(f"the operator {type(bad[0]).__name__} in {_source(node, expression)}",
                expression)
    _reject(f"{_source(node, expression)} ({type(node).__name__})", expression)


def parse_expression(expression) -> ast.Expression:
    """The checked syntax tree of ``expression``; :class:`ConfigError` for anything not
    allowed (see the module doc). Evaluates nothing: call it to check a configuration."""
    if not isinstance(expression, str):
        raise ConfigError(f"selector expression {expression!r} is of type "
                          f"{type(expression).__name__}, not a string. Fix: quote it, e.g. "
                          "expression: \"abs(x - 5) < 1e-6\".")
    text = expression.strip()
    if len(text) > MAX_LENGTH:
        _fail(expression, f"it is {len(text)} characters long (at most {MAX_LENGTH})",
              "shorten it; plane, box and nearest_curve criteria of the same selector are "
              "AND-ed with it.")
    if _bracket_depth(text) > MAX_DEPTH:
        _fail(expression, f"its brackets are nested {_bracket_depth(text)} deep (at most "
              f"{MAX_DEPTH})", "remove redundant brackets.")
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as err:
        _fail(expression, f"it is not valid Python syntax ({err.msg})",
              "write e.g. \"abs(x - 5) < 1e-6 and y > 0\".")
    except (RecursionError, MemoryError, ValueError) as err:  # parser stack; null bytes
        _fail(expression, f"Python cannot parse it ({type(err).__name__}: {err})",
              f"write a shorter, less nested formula (at most {MAX_DEPTH} levels).")
    stack = [(tree.body, 1)]  # iterative walk: no recursion before the depth is known
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            _fail(expression, f"operators and calls are nested more than {MAX_DEPTH} levels "
                  "deep", "simplify the formula (e.g. drop repeated signs or nots).")
        stack.extend((child, depth + 1) for child in _children(node, text))
    return tree


def _evaluate(node, env: dict):
    """Value of a checked node on the read-only arrays of ``env`` (recursion ≤ MAX_DEPTH)."""
    if isinstance(node, ast.Constant):
        return np.float64(node.value)  # float arithmetic: 9**9**9 overflows to inf, fast
    if isinstance(node, ast.Name):
        return env[node.id] if node.id in env else CONSTANTS[node.id]
    if isinstance(node, ast.BinOp):
        return _BINARY[type(node.op)](_evaluate(node.left, env), _evaluate(node.right, env))
    if isinstance(node, ast.UnaryOp):
        return _UNARY[type(node.op)](_evaluate(node.operand, env))
    if isinstance(node, ast.BoolOp):
        combine = np.logical_and if isinstance(node.op, ast.And) else np.logical_or
        out = _evaluate(node.values[0], env)
        for v in node.values[1:]:
            out = combine(out, _evaluate(v, env))
        return out
    if isinstance(node, ast.Compare):
        left, out = _evaluate(node.left, env), True
        for op, right_node in zip(node.ops, node.comparators):
            right = _evaluate(right_node, env)
            out = np.logical_and(out, _COMPARE[type(op)](left, right))
            left = right
        return out
    return FUNCTIONS[node.func.id][0](*(_evaluate(a, env) for a in node.args))  # ast.Call


def _variables(points) -> dict:
    """Read-only (N,) arrays of the variables at ``points`` (N, 3), copied from them."""
    P = np.array(points, dtype=np.float64, copy=True)
    if P.ndim != 2 or P.shape[1] != 3:
        raise ConfigError(f"a selector expression needs points of shape (N, 3), got {P.shape}.")
    x, y, z = P.T
    rho = np.hypot(x, y)
    env = {"x": x, "y": y, "z": z, "r": np.sqrt(rho**2 + z**2), "rho": rho,
           "theta": np.arctan2(rho, z), "phi": np.arctan2(y, x)}
    P.flags.writeable = False  # x, y, z are views of P
    for value in env.values():
        value.flags.writeable = False
    return env


def evaluate_expression(expression, points) -> np.ndarray:
    """(N,) bool: the checked boolean ``expression`` at ``points`` (N, 3), which it cannot
    modify. :class:`ConfigError` if it is not allowed or not one true/false value per point."""
    tree = parse_expression(expression)
    env = _variables(points)
    try:
        with np.errstate(all="ignore"):
            value = np.asarray(_evaluate(tree.body, env))
    except (TypeError, ValueError, ArithmeticError) as err:  # e.g. -(x > 0): no bool negative
        _fail(expression, f"numpy cannot evaluate it ({err})",
              "use arithmetic on numbers and not/and/or on comparisons.")
    if value.dtype != bool:
        _fail(expression, f"it gives {value.dtype} values, not true/false",
              "compare something, e.g. \"abs(x - 5) < 1e-6\".")
    if value.shape != env["x"].shape:
        got = f"the single value {bool(value)}" if value.ndim == 0 else f"shape {value.shape}"
        _fail(expression, f"it gives {got}, not one value per point (it must use a variable)",
              f"compare a variable ({', '.join(VARIABLES)}), e.g. \"z > 0\".")
    return value


def evaluate_values(expression, points) -> np.ndarray:
    """(N,) float: the checked arithmetic ``expression`` (same grammar as selectors, e.g. a
    source term "(12 + 1) * z * (5 * z**2 - 3) / 2") at ``points`` (N, 3). A constant
    expression gives the constant at every point; a true/false result or a NaN/inf value is
    refused with a :class:`ConfigError`."""
    tree = parse_expression(expression)
    env = _variables(points)
    try:
        with np.errstate(all="ignore"):
            value = np.asarray(_evaluate(tree.body, env))
    except (TypeError, ValueError, ArithmeticError) as err:
        _fail(expression, f"numpy cannot evaluate it ({err})", "use arithmetic on numbers.")
    if value.dtype == bool or value.dtype.kind not in "iuf":
        _fail(expression, f"it gives {value.dtype} values, not numbers",
              "write an arithmetic expression, e.g. \"x * y\".")
    value = np.broadcast_to(value.astype(np.float64), env["x"].shape).copy()
    if not np.all(np.isfinite(value)):
        bad = int(np.flatnonzero(~np.isfinite(value))[0])
        _fail(expression, f"it is not finite at point {bad} ({np.asarray(points)[bad].tolist()})",
              "keep it finite on the surface (guard divisions and logarithms).")
    return value
