"""Checks shared by the approximants: the parameter constraints their Configs share
(checked by :func:`pointatlas.constraints.validate_parameters` in ``fit``/``evaluate`` and at
start-up), the rules that need the nodes, node sets, evaluation points."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.constraints import Interval, Options
from pointatlas.errors import ConfigError, InputError
from pointatlas.pointcloud import check_distinct, validate_points

OUTSIDE_CHOICES = ("error", "flag")

#: nodal locality β_a = γ/h_a², support cut-off, nodal spacing h_a, points outside the domain
LOCALITY_CONSTRAINTS = {
    "gamma": [Interval(float, 0, None, closed="neither")],
    "tol": [Interval(float, 0, 1, closed="neither")],
    # None: 2·d; below the number of nodes (checked in fit, :func:`spacing_neighbors`)
    "n_spacing_neighbors": [Interval(int, 1, None), None],
    "outside": [Options(OUTSIDE_CHOICES)],
}

#: the dual's Newton solve (LME and the bases on LME's domain)
NEWTON_CONSTRAINTS = {
    **LOCALITY_CONSTRAINTS,
    "newton_tol": [Interval(float, 0, None, closed="neither")],
    "max_iter": [Interval(int, 1, None)],
}


@dataclass
class LocalityConfig:
    """The settings every approximant on nodal Gaussian supports has (β_a = γ/h_a²): a
    plugin's ``Config`` derives from this and restates ``gamma`` and ``tol`` with its own
    defaults. Meaning of each: :class:`.lme.LocalMaxEnt`."""
    gamma: float
    tol: float
    n_spacing_neighbors: Optional[int] = None
    outside: str = "error"

    parameter_constraints: ClassVar[dict[str, list]] = LOCALITY_CONSTRAINTS


@dataclass
class NewtonLocalityConfig(LocalityConfig):
    """:class:`LocalityConfig` and the settings of LME's Newton solve of the dual."""
    newton_tol: float = 1e-12
    max_iter: int = 100

    parameter_constraints: ClassVar[dict[str, list]] = NEWTON_CONSTRAINTS


def spacing_neighbors(value, dim: int, n_nodes: int, *, plugin: str) -> int:
    """The number of neighbours defining h_a: ``value`` (an integer >= 1, declared in
    :data:`LOCALITY_CONSTRAINTS`) or, if None, 2·d (exact on grids); fewer than the nodes."""
    k = 2 * dim if value is None else int(value)
    if k >= n_nodes:
        raise InputError(
            f"{plugin}: n_spacing_neighbors = {k} needs more than {k} nodes, got {n_nodes}. "
            "Give more nodes or lower n_spacing_neighbors."
        )
    return k


def check_nodes(nodes, *, plugin: str, min_nodes: int | None = None) -> np.ndarray:
    """Finite, distinct (n, d) nodes with n > d (or n >= ``min_nodes``)."""
    X = validate_points(nodes, what=f"{plugin} nodes")
    n, d = X.shape
    need = d + 1 if min_nodes is None else min_nodes
    if n < need:
        raise InputError(
            f"{plugin}: {n} node(s) in dimension {d}; need at least {need} (n > d) for the "
            "basis functions to exist. Give more nodes."
        )
    check_distinct(X, what=f"{plugin} nodes")
    return X


def check_points(points, dim: int, *, plugin: str) -> np.ndarray:
    X = validate_points(points, what=f"{plugin} evaluation points", min_points=0)
    if X.shape[1] != dim:
        raise InputError(
            f"{plugin}: evaluation points have dimension {X.shape[1]} but the nodes have "
            f"dimension {dim}; give points of shape (m, {dim})."
        )
    return X


def check_order(order, max_order: int, *, plugin: str) -> int:
    if isinstance(order, bool) or order not in tuple(range(max_order + 1)):
        raise ConfigError(
            f"{plugin}: order = {order!r} is invalid; use 0 (values), 1 (+ gradients)"
            + (" or 2 (+ Hessians)." if max_order >= 2 else ".")
        )
    return int(order)


def compact_rows(indptr, keep_row, *arrays):
    """Drop the entries of rows where ``keep_row`` is False; returns new indptr and arrays."""
    counts = np.diff(indptr) * keep_row
    entry_keep = np.repeat(keep_row, np.diff(indptr))
    new_indptr = np.zeros_like(indptr)
    np.cumsum(counts, out=new_indptr[1:])
    return new_indptr, [None if a is None else a[entry_keep] for a in arrays]


def replace_rows(indptr, arrays, rows, sub_indptr, sub_arrays):
    """CSR with the entries of ``rows`` replaced by the rows of (sub_indptr, sub_arrays)."""
    m = len(indptr) - 1
    counts = np.diff(indptr)
    old_row = np.repeat(np.arange(m), counts)
    counts[rows] = np.diff(sub_indptr)
    new_indptr = np.zeros_like(indptr)
    np.cumsum(counts, out=new_indptr[1:])
    keep = np.ones(m, dtype=bool)
    keep[rows] = False
    kept = np.flatnonzero(keep[old_row])
    dst_old = new_indptr[old_row[kept]] + (kept - indptr[old_row[kept]])
    sub_row = np.repeat(np.arange(len(rows)), np.diff(sub_indptr))
    j = np.arange(len(sub_row))
    dst_sub = new_indptr[rows[sub_row]] + (j - sub_indptr[sub_row])
    out = []
    for a, b in zip(arrays, sub_arrays):
        if a is None:
            out.append(None)
            continue
        c = np.empty((new_indptr[-1],) + a.shape[1:], dtype=a.dtype)
        c[dst_old] = a[kept]
        c[dst_sub] = b
        out.append(c)
    return new_indptr, out
