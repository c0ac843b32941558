"""The tangent of an atlas too large to hold its basis: chart groups as tasks that rebuild
their charts' basis, assemble their part of K and drop the basis again.

The kit's :class:`~.atlas_quadrature.AtlasQuadrature` keeps p_a and its chart derivatives at
every Gauss point: about 90 nodes × 7 words × 8 bytes per point and some 40 Gauss points
per sample, i.e. ~0.25 MB per sample and ~50 GB at 2·10⁵ samples
(:func:`pointatlas_atlas.memory_estimate.estimate_atlas_bytes` with ``keep_basis``). One
assembly (a linear problem's K) needs each point's basis once, so here the atlas keeps only
its charts and Gauss points (``build_quadrature(keep_basis=False)``) and each task, for a
group of charts,

1. evaluates each chart's approximant at its stored Gauss points ξ_g (what
   :func:`pointatlas_atlas.chart.chart_quadrature` evaluated and dropped),
2. packs them as an :class:`~.atlas_quadrature.AtlasQuadrature` of the group
   (:func:`~.atlas_quadrature.pack_quadrature`) and assembles its part
   K_g = Σ_{q ∈ g} w_q Φ_qᵀ ∂²W/∂y² Φ_q (thesis Eq. 15) with the kit's
   :class:`~.assembler.Assembler`,
3. returns the node-block rows the part touches.

K = Σ_g K_g is summed on the client in the order of the groups (:func:`sum_block_parts`), so
the result does not depend on where the tasks ran. Memory: one group's basis per worker
thread, the parts (each node pair shared by points of several groups is counted in each)
and K on the client. Groups are runs of charts in Morton order of their centres, so a
group is compact and its part has few rows it shares with other groups.
"""
from __future__ import annotations

import dataclasses
import gc

import numpy as np
from numba import njit
from scipy.sparse import bsr_matrix

from pointatlas.errors import InputError
from pointatlas.executor import current_executor

#: Gauss points per group: ~0.25 GB of basis (order 2, 90 nodes) and ~1 s of work a task
GROUP_POINTS = 40_000


def morton_order(centres: np.ndarray) -> np.ndarray:
    """Indices sorting points (n, D) along a Z-order (Morton) curve of 21 bits per axis (63
    bits: points in D > 3 are ordered by their first three principal components)."""
    c = np.asarray(centres, dtype=np.float64)
    if c.shape[1] > 3:
        c = c - c.mean(axis=0)
        c = c @ np.linalg.svd(c, full_matrices=False)[2][:3].T
    lo, span = c.min(axis=0), np.ptp(c, axis=0)
    grid = ((c - lo) / np.where(span > 0, span, 1.0) * (2 ** 21 - 1)).astype(np.uint64)
    code = np.zeros(len(c), np.uint64)
    for bit in range(21):
        for axis in range(c.shape[1]):
            code |= ((grid[:, axis] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(
                bit * c.shape[1] + axis)
    return np.argsort(code, kind="stable")


def chart_groups(quadrature: list, group_points: int = GROUP_POINTS) -> list[np.ndarray]:
    """Chart ids in groups of about ``group_points`` Gauss points, compact in space: runs of
    the charts (those with points) in Morton order of their Gauss points' centroid."""
    if group_points < 1:
        raise InputError(f"group_points must be ≥ 1 (got {group_points}).")
    ids = np.array([k for k, c in enumerate(quadrature) if len(c.weights)], np.int64)
    if ids.size == 0:
        raise InputError("the atlas has no Gauss points: build its quadrature first.")
    centres = np.array([quadrature[k].positions.mean(axis=0) for k in ids])
    ids = ids[morton_order(centres)]
    sizes = np.array([len(quadrature[k].weights) for k in ids])
    n = max(1, int(round(sizes.sum() / group_points)))
    cuts = np.searchsorted(np.cumsum(sizes), sizes.sum() * np.arange(1, n) / n)
    return [g for g in np.split(ids, np.unique(cuts)) if g.size]


def with_basis(chart, quadrature, order: int):
    """The chart's ChartQuadrature with its basis at its Gauss points (global node ids),
    derivatives to ``order`` (≥ 1: the chart map's tangents need them)."""
    b = chart.approximant.evaluate(quadrature.xi, order=max(order, 1))
    if b.outside is not None and b.outside.any():
        raise InputError(f"{int(b.outside.sum())} Gauss point(s) of a chart lie outside its "
                         "basis's domain although the chart kept them; rebuild the atlas.")
    return dataclasses.replace(quadrature, basis=b.renumbered(chart.node_index))


def tangent_of_charts(shared: dict, item: tuple):
    """A task: the tangent part of charts ``item`` = (ids, charts, Gauss points) as
    (rows, row lengths, cols, blocks (nnz, B, B)) of the node-block rows it touches (with
    ``shared['upper']`` the blocks of cols ≥ row only)."""
    from .assembler import Assembler
    from .atlas_quadrature import pack_quadrature

    ids, charts, quads = item
    order = shared["order"]
    parts = [(int(k), with_basis(ch, cq, order)) for k, ch, cq in zip(ids, charts, quads)]
    q = pack_quadrature(parts, shared["signs"], shared["layout"].n_nodes, order)
    del parts
    asm = Assembler(q, shared["layout"], shared["energies"])
    blocks = asm.tangent_data(shared["U"])   # this process's threads (one on a worker)
    plan = q.assembly_plan()
    lengths = np.diff(plan.row_ptr)
    cols = plan.cols
    if shared["upper"]:
        row_of = np.repeat(np.arange(len(lengths)), lengths)
        keep = cols >= row_of
        cols, blocks = cols[keep], blocks[keep]
        lengths = np.bincount(row_of[keep], minlength=len(lengths))
    rows = np.flatnonzero(lengths)
    del asm, q
    # a tangent call leaves ~6 500 objects in reference cycles, some holding the group's
    # arrays (measured: 0.05–0.5 GiB per 40 000 Gauss points, a local run at 2·10⁴ points
    # reached 7.5 GiB): collected here so that a process holds one group at a time
    gc.collect()
    return rows, lengths[rows], cols, blocks


@njit(cache=True)
def _scatter_part(rows, lengths, cols, data, cursor, out_cols, out_data):
    """Append a part's rows to the bucketed arrays at ``cursor[row]`` (advanced)."""
    k = 0
    for i in range(len(rows)):
        r = rows[i]
        for _ in range(lengths[i]):
            out_cols[cursor[r]] = cols[k]
            out_data[cursor[r]] = data[k]
            cursor[r] += 1
            k += 1


@njit(cache=True)
def _merge_rows(ptr, cols, data, new_ptr):
    """Per row: sort its entries by column (stable: parts keep their order) and sum equal
    columns, compacting the arrays in place; ``new_ptr`` gets the merged row pointers."""
    w = 0
    new_ptr[0] = 0
    for r in range(len(ptr) - 1):
        a, b = ptr[r], ptr[r + 1]
        seg_cols = cols[a:b].copy()
        seg_data = data[a:b].copy()
        order = np.argsort(seg_cols, kind="mergesort")
        last = -1
        for t in order:
            c = seg_cols[t]
            if c != last:
                cols[w] = c
                data[w] = seg_data[t]
                w += 1
                last = c
            else:
                data[w - 1] += seg_data[t]
        new_ptr[r + 1] = w
    return w


def sum_block_parts(parts: list, n_nodes: int, block: int):
    """Σ of the parts (rows, lengths, cols, blocks) as a scipy BSR (n_nodes·B)², summing in
    the order of ``parts``; each part is freed (the list emptied) once it is copied."""
    counts = np.zeros(n_nodes, np.int64)
    for rows, lengths, _, _ in parts:
        counts[rows] += lengths
    ptr = np.concatenate([[0], np.cumsum(counts)])
    cols = np.empty(ptr[-1], np.int64)
    data = np.empty((ptr[-1], block, block))
    cursor = ptr[:-1].copy()
    while parts:
        _scatter_part(*parts.pop(0), cursor, cols, data)
    new_ptr = np.empty(n_nodes + 1, np.int64)
    nnz = _merge_rows(ptr, cols, data, new_ptr)
    del cursor
    cols.resize(nnz, refcheck=False)            # shrink in place (realloc): no second copy
    data.resize((nnz, block, block), refcheck=False)
    return bsr_matrix((data, cols, new_ptr), shape=(n_nodes * block, n_nodes * block),
                      blocksize=(block, block))


def streamed_tangent(atlas, layout, energies, U=None, order: int = 2,
                     group_points: int = GROUP_POINTS, upper: bool = False):
    """K = ∂²Π/∂U² of ``energies`` over ``layout`` on an atlas built with
    ``build_quadrature(keep_basis=False)``, as a scipy BSR matrix of B × B node blocks
    (``.tocsr()`` for the solvers), group by group on the run's executor (module docstring).
    ``U`` (n_nodes, B) or (n_dofs,) defaults to zero (the linear problem's K). ``upper``:
    only the node blocks K_ab with b ≥ a (K is symmetric: K = U + Uᵀ − blockdiag U), half
    the memory of the parts and of K."""
    quads = getattr(atlas, "quadrature_", None)
    if not quads:
        raise InputError("the atlas has no quadrature: call atlas.build_quadrature(...) "
                         "before streamed_tangent.")
    U = np.zeros((layout.n_nodes, layout.block)) if U is None else layout.as_blocks(U)
    signs = np.asarray(getattr(atlas, "chart_orientation_", np.ones(len(quads))), float)
    groups = chart_groups(quads, group_points)
    items = [(g, [atlas.charts_[k] for k in g], [quads[k] for k in g]) for g in groups]
    shared = dict(order=order, signs=signs, layout=layout, energies=list(energies), U=U,
                  upper=bool(upper))
    P = atlas.points_
    labels = [f"charts {', '.join(map(str, g[:3]))}{', …' if len(g) > 3 else ''} "
              f"({sum(len(quads[k].weights) for k in g)} Gauss points near "
              f"({', '.join(f'{v:.3g}' for v in P[atlas.charts_[g[0]].node_index].mean(0))}))"
              for g in groups]
    parts = current_executor().map(tangent_of_charts, items, shared=shared,
                                   desc="streamed tangent", labels=labels, min_tasks=len(items),
                                   costs=[sum(len(quads[k].weights) for k in g) for g in groups])
    del items
    return sum_block_parts(parts, layout.n_nodes, layout.block)
