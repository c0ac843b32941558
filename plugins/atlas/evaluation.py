"""The atlas's basis functions at chosen surface points, in global node numbering.

A field on the atlas is u(x) = Σ_a p_a(ξ) U_a with p_a the LME basis of a chart κ that
contains x and ξ its chart preimage (thesis Eq. 2, §3.3). At a control point x_a itself the
natural chart is the one whose patch PU ψ_κ is largest there, with ξ = Ξ_κ[a] (the control
point's own embedded coordinates), so no projection is needed.
"""
from __future__ import annotations

import numpy as np

from pointatlas.basis import BasisFunctions
from pointatlas.errors import InputError

from .partition import label_groups


def node_charts(atlas, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For control points ``nodes`` (global ids): the chart with the largest ψ_κ at each,
    among the charts that hold it as a control point, and its local index there.

    Returns (chart (k,), local (k,)). Raises :class:`InputError` for a node in no chart.
    """
    nodes = np.asarray(nodes, dtype=np.int64)
    psi = atlas.patch_pu(atlas.points_[nodes]).toarray()  # (k, L)
    chart = np.full(nodes.size, -1, dtype=np.int64)
    local = np.full(nodes.size, -1, dtype=np.int64)
    best = np.full(nodes.size, -np.inf)
    for k, c in enumerate(atlas.charts_):
        where = np.full(atlas.points_.shape[0], -1, dtype=np.int64)
        where[c.node_index] = np.arange(c.node_index.size)
        loc = where[nodes]
        # prefer charts where the node is not on the hull of Ξ_κ: ψ_κ, then any holder
        score = np.where(loc >= 0, psi[:, k], -np.inf)
        better = score > best
        chart[better], local[better], best[better] = k, loc[better], score[better]
    if (chart < 0).any():
        bad = nodes[chart < 0]
        raise InputError(f"{bad.size} point(s) (first: {bad[:5].tolist()}) belong to no chart "
                         "of the atlas; build the atlas on all the points you evaluate at.")
    return chart, local


def basis_at(atlas, chart: np.ndarray, xi: np.ndarray, order: int = 1) -> BasisFunctions:
    """The basis functions p_a (global node ids) at chart points (chart[i], xi[i]).

    Rows keep the input order; an evaluation outside its chart's domain raises
    :class:`InputError` naming the point.
    """
    chart = np.asarray(chart, dtype=np.int64)
    xi = np.atleast_2d(np.asarray(xi, dtype=np.float64))
    parts, rows = [], []
    for k, sel in label_groups(chart):
        c = atlas.charts_[k]
        b = c.approximant.evaluate(xi[sel], order=order)
        if b.outside is not None and b.outside.any():
            i = sel[np.flatnonzero(b.outside)[0]]
            why = getattr(c.approximant, "refusal", lambda j: None)(int(np.flatnonzero(
                b.outside)[0]))
            if why:
                raise InputError(f"point {i} (ξ = {xi[i].tolist()}) of chart {k}: {why}")
            raise InputError(f"point {i} (ξ = {xi[i].tolist()}) lies outside chart {k}'s domain; "
                             "evaluate at points inside the sampled surface.")
        parts.append(b.renumbered(c.node_index))
        rows.append(sel)
    return stack_rows(parts, np.concatenate(rows))


def basis_at_nodes(atlas, nodes: np.ndarray, order: int = 1):
    """(basis, chart, xi) at control points ``nodes``: each in its best chart (node_charts)."""
    chart, local = node_charts(atlas, nodes)
    xi = np.stack([atlas.charts_[k].xi_nodes[j] for k, j in zip(chart, local)]) \
        if len(chart) else np.zeros((0, atlas.charts_[0].xi_nodes.shape[1]))
    return basis_at(atlas, chart, xi, order), chart, xi


def stack_rows(parts: list[BasisFunctions], rows: np.ndarray) -> BasisFunctions:
    """Concatenate row blocks, then put rows back in the order given by ``rows``."""
    counts = np.concatenate([np.diff(p.indptr) for p in parts])
    indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)

    def cat(attr):
        vals = [getattr(p, attr) for p in parts]
        return None if any(v is None for v in vals) else np.concatenate(vals)

    stacked = BasisFunctions(indptr=indptr, indices=cat("indices"), values=cat("values"),
                             gradients=cat("gradients"), hessians=cat("hessians"))
    order = np.empty_like(rows)
    order[rows] = np.arange(rows.size)
    return stacked.take(order)
