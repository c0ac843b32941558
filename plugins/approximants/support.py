"""Nodal spacing, nodal locality and the support neighbours of evaluation points.

Both approximants use Gaussian weights ``exp(-β_a |x - x_a|²)`` with a nodal locality
``β_a = γ / h_a²`` (thesis Box 2, Rosolen et al. 2010: uniform aspect ratio γ = β_a h_a²) and
cut them off where the weight drops below ``tol``, i.e. outside the radius
``r_a = sqrt(-ln(tol) / β_a)``. This module computes ``h_a``, ``β_a``, ``r_a`` and, for many
evaluation points, the CSR list of nodes whose support contains each point.

Neighbour search: a uniform cell grid in which each node is registered in every cell its support
touches (numba kernels) for d ≤ 4; a scipy cKDTree ball query (radius max r_a, then filtered
by each node's own r_a) above.
"""
from __future__ import annotations

from contextlib import contextmanager

from dataclasses import dataclass

import numba as nb
import numpy as np
from scipy.spatial import cKDTree

#: Largest dimension handled by the cell grid; above it the kd-tree path is used.
GRID_MAX_DIM = 4


def nodal_spacing(tree: cKDTree, nodes: np.ndarray, n_neighbors: int) -> np.ndarray:
    """h_a: mean distance from node a to its ``n_neighbors`` nearest other nodes (length units).

    On a Cartesian grid of spacing h with ``n_neighbors = 2d`` this is exactly h.
    """
    dist, _ = tree.query(nodes, k=n_neighbors + 1, workers=-1)
    return dist[:, 1:].mean(axis=1)


def locality(h: np.ndarray, gamma: float) -> np.ndarray:
    """β_a = γ / h_a² (1/length²), thesis Box 2."""
    return gamma / h**2


def support_radius(beta: np.ndarray, tol: float) -> np.ndarray:
    """r_a = sqrt(-ln(tol)/β_a): beyond it exp(-β_a r²) < tol and the node is dropped."""
    return np.sqrt(-np.log(tol) / beta)


class RebuildsCellLists:
    """Mixin of a fitted basis whose cell lists (``grid_`` and what ``_build_grid`` derives
    from it) are left out when it is pickled, e.g. sent to or from a Dask worker, and rebuilt
    identically on first use. They hold ~70 entries a node for d = 2 (about 20 times the
    nodes themselves), more for d = 3."""

    _cell_list_attributes: tuple = ("grid_",)

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        for name in self._cell_list_attributes:
            state.pop(name, None)
        return state

    def __getattr__(self, name: str):
        # only reached when the attribute is missing: the cell lists of an unpickled basis
        if name in type(self)._cell_list_attributes and "radius_" in self.__dict__:
            self._build_grid()
            return self.__dict__[name]
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")


class SupportGrid:
    """Cell lists for repeated support-neighbour queries with per-node radii.

    Every node is registered in all cells of a uniform grid that its support ball's bounding
    box touches; a query then scans only the cell containing the point and keeps the nodes
    with |x - x_a| < r_a. Cell side ≈ a fraction of the median radius (few candidates per
    point even when the radii vary a lot). Dimensions above GRID_MAX_DIM use a kd-tree.
    """

    def __init__(self, nodes: np.ndarray, radii: np.ndarray):
        self.nodes = np.ascontiguousarray(nodes, dtype=np.float64)
        radii = np.ascontiguousarray(radii, dtype=np.float64)
        self.radii2 = radii**2
        n, d = self.nodes.shape
        self.r_max = float(radii.max())
        if d > GRID_MAX_DIM:
            self.tree = cKDTree(self.nodes)
            return
        self.tree = None
        lo = (self.nodes - radii[:, None]).min(axis=0)
        extent = (self.nodes + radii[:, None]).max(axis=0) - lo
        # cell side: fewer candidates per point (≈ 1.4 × the support nodes for d = 2) against
        # more entries (each node in ≈ 70 cells for d = 2)
        cell = float(np.median(radii)) * (0.35 if d == 2 else 0.25 * d)
        max_cells = max(16 * n, 4096)
        while np.prod(np.floor(extent / cell) + 1.0) > max_cells:
            cell *= 1.25
        shape = (np.floor(extent / cell) + 1).astype(np.int64)
        strides = np.ones(d, dtype=np.int64)
        for k in range(d - 2, -1, -1):
            strides[k] = strides[k + 1] * shape[k + 1]
        self.lo, self.cell, self.shape, self.strides = lo, cell, shape, strides
        self.starts, self.entries = _register(self.nodes, radii, lo, cell, shape, strides)
        # copies per entry so that a cell scan streams through contiguous memory
        self.entry_x = np.ascontiguousarray(self.nodes[self.entries].T)
        self.entry_r2 = self.radii2[self.entries]

    def cells(self, points: np.ndarray) -> Cells:
        """The candidate list of every point (see :class:`Cells`)."""
        points = np.ascontiguousarray(points, dtype=np.float64)
        m = len(points)
        if self.tree is not None:  # one "cell" per point: its filtered kd-tree ball
            indptr, indices = self._query_tree(points)
            return Cells(points, np.arange(m, dtype=np.int64), indptr, indices,
                         np.ascontiguousarray(self.nodes[indices].T), self.radii2[indices],
                         np.arange(m, dtype=np.int64))
        cid = np.empty(m, dtype=np.int64)
        _cell_ids(points, self.lo, self.cell, self.shape, self.strides, cid)
        visit = visit_order(cid, len(self.starts) - 1)
        return Cells(points, cid, self.starts, self.entries, self.entry_x, self.entry_r2, visit)

    def cells_within(self, points: np.ndarray, radius: float) -> Cells:
        """Candidate lists with one radius for all nodes (a wider net for retried points)."""
        points = np.ascontiguousarray(points, dtype=np.float64)
        m = len(points)
        tree = self.tree if self.tree is not None else cKDTree(self.nodes)
        lists = tree.query_ball_point(points, radius, workers=-1, return_sorted=True)
        indptr, indices = _flatten(lists)
        return Cells(points, np.arange(m, dtype=np.int64), indptr, indices,
                     np.ascontiguousarray(self.nodes[indices].T),
                     np.full(len(indices), np.inf), np.arange(m, dtype=np.int64))

    def query(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """CSR (indptr (m+1,), indices (nnz,)) of the nodes a with |x_i - x_a| < r_a."""
        cells = self.cells(points)
        indptr = cells.count()
        indices = np.empty(indptr[-1], dtype=np.int64)
        _fill_kernel(*cells.args(), indptr, indices)
        return indptr, indices

    def _query_tree(self, points):
        lists = self.tree.query_ball_point(points, self.r_max, workers=-1, return_sorted=True)
        indptr, cand = _flatten(lists)
        row = np.repeat(np.arange(len(points)), np.diff(indptr))
        keep = ((points[row] - self.nodes[cand]) ** 2).sum(axis=1) < self.radii2[cand]
        indptr = np.zeros(len(points) + 1, dtype=np.int64)
        np.cumsum(np.bincount(row[keep], minlength=len(points)), out=indptr[1:])
        return indptr, cand[keep]


@contextmanager
def threads_for(n_points: int, small: int = 64):
    """Run numba's parallel kernels on one thread for fewer than ``small`` points: waking the
    thread team costs milliseconds when the cores are busy (measured 6 ms against 0.09 ms for
    one LME point with OpenMP on two shared cores), far more than the work."""
    if n_points >= small:
        yield
        return
    previous = nb.get_num_threads()
    nb.set_num_threads(1)
    try:
        yield
    finally:
        nb.set_num_threads(previous)


def _flatten(lists) -> tuple[np.ndarray, np.ndarray]:
    """CSR (indptr, indices) of a sequence of index lists."""
    counts = np.fromiter((len(li) for li in lists), dtype=np.int64, count=len(lists))
    indptr = np.zeros(len(lists) + 1, dtype=np.int64)
    np.cumsum(counts, out=indptr[1:])
    indices = (np.concatenate([np.asarray(li, dtype=np.int64) for li in lists])
               if indptr[-1] else np.empty(0, dtype=np.int64))
    return indptr, indices


@dataclass
class Cells:
    """Candidate support nodes of m points, for the numba kernels.

    The candidates of point i are the entries ``starts[cell[i]] : starts[cell[i] + 1]``
    (none if ``cell[i] < 0``); entry e is node ``entries[e]`` at ``entry_x[:, e]`` with
    squared support radius ``entry_r2[e]``; a candidate is a support node when
    |x_i - x_a|² < r_a². ``visit`` orders the points so that neighbours are processed together.
    """

    points: np.ndarray
    cell: np.ndarray
    starts: np.ndarray
    entries: np.ndarray
    entry_x: np.ndarray
    entry_r2: np.ndarray
    visit: np.ndarray

    def args(self):
        return (self.points, self.visit, self.cell, self.starts, self.entries, self.entry_x,
                self.entry_r2)

    def count(self) -> np.ndarray:
        """indptr (m+1,) of the CSR layout of the support nodes of every point."""
        counts = np.empty(len(self.points), dtype=np.int64)
        with threads_for(len(self.points)):
            if self.points.shape[1] == 2:
                _count_kernel_2d(*self.args(), counts)
            else:
                _count_kernel(*self.args(), counts)
        indptr = np.zeros(len(self.points) + 1, dtype=np.int64)
        np.cumsum(counts, out=indptr[1:])
        return indptr


@nb.njit(cache=True)
def _register(nodes, radii, lo, cell, shape, strides):
    """CSR cell -> node lists, each node in every cell its support ball reaches: the cells of
    the ball's bounding box nearer to the node than r_a + 1e-6 cell (a margin for round-off in
    the cell of a point). Registering by ball, not box, trims ~15% of the candidates (d = 2).
    """
    n, d = nodes.shape
    n_cells = 1
    for k in range(d):
        n_cells *= shape[k]
    counts = np.zeros(n_cells + 1, dtype=np.int64)
    first = np.empty(d, dtype=np.int64)
    last = np.empty(d, dtype=np.int64)
    cur = np.empty(d, dtype=np.int64)
    starts = np.zeros(n_cells + 1, dtype=np.int64)
    entries = np.empty(0, dtype=np.int64)
    for sweep in range(2):
        if sweep == 1:
            for c in range(n_cells):
                starts[c + 1] = starts[c] + counts[c]
            entries = np.empty(starts[n_cells], dtype=np.int64)
            counts[:] = 0
        for a in range(n):
            ra = radii[a] + 1e-6 * cell  # margin for round-off in the cell of a point
            r2 = ra * ra
            for k in range(d):
                first[k] = min(max(int(np.floor((nodes[a, k] - radii[a] - lo[k]) / cell)), 0),
                               shape[k] - 1)
                last[k] = min(max(int(np.floor((nodes[a, k] + radii[a] - lo[k]) / cell)), 0),
                              shape[k] - 1)
                cur[k] = first[k]
            while True:
                cid = 0
                gap2 = 0.0  # squared distance from node a to the cell (a box)
                for k in range(d):
                    cid += cur[k] * strides[k]
                    c_lo = lo[k] + cur[k] * cell
                    g = max(c_lo - nodes[a, k], nodes[a, k] - (c_lo + cell), 0.0)
                    gap2 += g * g
                if gap2 <= r2:  # the support ball reaches the cell
                    if sweep == 1:
                        entries[starts[cid] + counts[cid]] = a
                    counts[cid] += 1
                k = d - 1
                while k >= 0 and cur[k] == last[k]:
                    cur[k] = first[k]
                    k -= 1
                if k < 0:
                    break
                cur[k] += 1
    return starts, entries


@nb.njit(parallel=True, cache=True)
def _cell_ids(points, lo, cell, shape, strides, cid):
    """cid[i]: the grid cell containing point i, -1 outside the grid (or NaN coordinates)."""
    m, d = points.shape
    for i in nb.prange(m):
        c = 0
        for k in range(d):
            t = (points[i, k] - lo[k]) / cell
            if not (t >= 0.0 and t < shape[k]):
                c = -1
                break
            c += int(t) * strides[k]
        cid[i] = c


def visit_order(cid: np.ndarray, n_cells: int) -> np.ndarray:
    """The points in order of their cell (those outside the grid first), stable: a counting
    sort over the cells when they are few, else a comparison sort of the m points. The
    counting sort touches every cell of the grid (up to 16 per node: 1.6·10⁷ for the
    partition of unity of 10⁶ points), so for the few hundred points of one chart it cost
    O(grid) a call, and the atlas's per-chart evaluations O(N^2) in all."""
    if n_cells <= 4 * len(cid):
        return _sort_by_cell(cid, n_cells)
    return np.argsort(cid, kind="stable")


@nb.njit(cache=True)
def _sort_by_cell(cid, n_cells):
    """The points in order of their cell (those outside the grid first), a stable counting
    sort: the same order as np.argsort(cid, kind="stable")."""
    first = np.zeros(n_cells + 2, dtype=np.int64)
    for c in cid:
        first[c + 2] += 1
    for c in range(1, n_cells + 2):
        first[c] += first[c - 1]
    visit = np.empty(len(cid), dtype=np.int64)
    for i in range(len(cid)):
        c = cid[i] + 1
        visit[first[c]] = i
        first[c] += 1
    return visit


@nb.njit(cache=True, inline="always")
def scan(x, cid, starts, entries, entry_x, entry_r2, out, pos, write):
    """Count (and write into out[pos:], if ``write``) the support nodes of x in cell ``cid``."""
    if cid < 0:
        return 0
    d = x.shape[0]
    count = 0
    for q in range(starts[cid], starts[cid + 1]):
        d2 = 0.0
        for k in range(d):
            t = x[k] - entry_x[k, q]
            d2 += t * t
        if d2 < entry_r2[q]:
            if write:
                out[pos + count] = q
            count += 1
    return count


@nb.njit(parallel=True, cache=True)
def _count_kernel(points, visit, cell, starts, entries, entry_x, entry_r2, counts):
    dummy = np.empty(0, dtype=np.int64)
    for ii in nb.prange(points.shape[0]):
        i = visit[ii]
        counts[i] = scan(points[i], cell[i], starts, entries, entry_x, entry_r2, dummy, 0,
                         False)


@nb.njit(parallel=True, cache=True)
def _count_kernel_2d(points, visit, cell, starts, entries, entry_x, entry_r2, counts):
    """:func:`_count_kernel` for d = 2, written out so that the scan of a cell vectorises."""
    for ii in nb.prange(points.shape[0]):
        i = visit[ii]
        ci = cell[i]
        if ci < 0:
            counts[i] = 0
            continue
        x0 = points[i, 0]
        x1 = points[i, 1]
        n = 0
        for q in range(starts[ci], starts[ci + 1]):
            t0 = x0 - entry_x[0, q]
            t1 = x1 - entry_x[1, q]
            n += np.int64(t0 * t0 + t1 * t1 < entry_r2[q])
        counts[i] = n


@nb.njit(parallel=True, cache=True)
def _fill_kernel(points, visit, cell, starts, entries, entry_x, entry_r2, indptr, indices):
    """indices[indptr[i]:indptr[i+1]] = the support nodes of point i."""
    for ii in nb.prange(points.shape[0]):
        i = visit[ii]
        lo = indptr[i]
        n = scan(points[i], cell[i], starts, entries, entry_x, entry_r2, indices, lo, True)
        for q in range(lo, lo + n):
            indices[q] = entries[indices[q]]
