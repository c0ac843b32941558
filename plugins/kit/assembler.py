"""One assembler for every energy: global energy, residual and sparse tangent on an atlas.

For energies W_e over fields laid out by a :class:`~.fields.FieldLayout` (DOFs B a + i),

    Π(U) = Σ_e Σ_q w_q W_e(jet_q(U)),   R = ∂Π/∂U,   K = ∂²Π/∂U²   (thesis Eq. 14–15),

with the jets and the scatter of :mod:`.assembly_kernels`. Work is threaded over point
blocks of the cached :class:`~.assembly_plan.AssemblyPlan` (the sparsity pattern is
computed once per quadrature and reused across Newton iterations and increments), and each
thread evaluates the energy kernels chunk by chunk, so the pointwise Hessians of only
``chunk`` points are in memory at a time.
"""
from __future__ import annotations

import itertools
from typing import Sequence

import numpy as np
from scipy.sparse import bsr_matrix

from pointatlas.errors import ConfigError
from pointatlas.executor import current_executor

from .assembly_kernels import jets_at, scatter_gradient, tangent_blocks
from .assembly_plan import balanced_ranges, n_threads, run_threads
from .fields import FieldLayout

#: points whose energy Hessians are held at once by one thread
CHUNK = 4096


class _Term:
    """An energy with its jet tables inside the global layout and its point data."""

    def __init__(self, energy, layout: FieldLayout, quadrature):
        names = [f.name for f in layout.fields]
        for f in energy.fields:
            if f.name not in names:
                raise ConfigError(f"energy {type(energy).__name__} uses field {f.name!r}, "
                                  f"which the physics does not declare (fields: {names}).")
            if layout.field(f.name) != f:
                raise ConfigError(f"energy {type(energy).__name__} declares field {f.name!r} "
                                  f"as {f}, the physics as {layout.field(f.name)}.")
            if f.order > quadrature.order:
                raise ConfigError(f"field {f.name!r} needs chart derivatives of order "
                                  f"{f.order}; the quadrature holds order {quadrature.order}.")
        idx = np.concatenate([np.arange(layout.jet_slice(f.name).start,
                                        layout.jet_slice(f.name).stop) for f in energy.fields])
        self.energy = energy
        self.index = idx.astype(np.int64)      # entries of the global jet this energy sees
        self.whole = len(idx) == layout.jet_size and np.array_equal(idx, np.arange(len(idx)))
        self.data = np.ascontiguousarray(energy.point_data(quadrature), dtype=np.float64)
        if self.data.ndim != 2 or len(self.data) != quadrature.n_points:
            raise ConfigError(f"{type(energy).__name__}.point_data must return an (m, n_data)"
                              f" array for m = {quadrature.n_points} points; got shape "
                              f"{self.data.shape}.")
        self.n_parts = len(energy.density_names)


#: numbers of the assemblers of this process (their keys on a distributed executor)
_SHARED_IDS = itertools.count()


class Assembler:
    """Energy, densities, residual and tangent of ``energies`` on ``quadrature``."""

    def __init__(self, quadrature, layout: FieldLayout, energies: Sequence):
        if layout.n_nodes != quadrature.n_nodes:
            raise ConfigError(f"the field layout has {layout.n_nodes} nodes, the quadrature "
                              f"{quadrature.n_nodes}.")
        self.q, self.layout = quadrature, layout
        self.terms = [_Term(e, layout, quadrature) for e in energies]
        used = {f.name for e in energies for f in e.fields}
        unused = [f.name for f in layout.fields if f.name not in used]
        if unused:
            raise ConfigError(f"field(s) {unused} are declared but no energy uses them: "
                              "remove them from the physics' fields or add the energy that "
                              "needs them.")
        # the key under which a distributed executor keeps this assembler's copy on the
        # cluster: a number no other assembler of this process gets (``id(self)`` is reused
        # once an assembler is freed, and a later one was then computed with the earlier
        # one's energies: a load residual on dask took another load's assembler)
        self._shared_id = next(_SHARED_IDS)
        self._data_version = 0
        self.part_names = [f"{type(t.energy).__name__}.{n}" if len(self.terms) > 1 else n
                           for t in self.terms for n in t.energy.density_names]

    def refresh_data(self) -> None:
        """Recompute every energy's point data (after the caller changed what it depends on,
        e.g. a degradation or a driving energy between the steps of a staggered solve)."""
        self.terms = [_Term(t.energy, self.layout, self.q) for t in self.terms]
        self._data_version += 1       # a distributed executor sends the new data

    # -- pointwise evaluation ------------------------------------------------------------
    def _evaluate(self, points, U, want):
        """(dens (n, n_parts), g (n, n_jet) | None, H (n, n_jet, n_jet) | None) at points."""
        L, q = self.layout, self.q
        jets = np.empty((len(points), L.jet_size))
        jets_at(points, q.indptr, q.indices, q.basis, U, L.jet_column, L.jet_dof, jets)
        dens, g, H = [], None, None
        if want >= 1:
            g = np.zeros((len(points), L.jet_size))
        if want >= 2:
            H = np.zeros((len(points), L.jet_size, L.jet_size))
        for t in self.terms:
            sub = jets if t.whole else np.ascontiguousarray(jets[:, t.index])
            d, ge, He = t.energy.evaluate(sub, t.data[points], want)
            dens.append(np.asarray(d).reshape(len(points), t.n_parts))
            if t.whole:
                if want >= 1:
                    g += ge
                if want >= 2:
                    H += He
            else:
                if want >= 1:
                    g[:, t.index] += ge
                if want >= 2:
                    H[:, t.index[:, None], t.index[None, :]] += He
        return np.concatenate(dens, axis=1), g, H

    def densities(self, U) -> np.ndarray:
        """(m, n_parts) energy density parts per reference area at every point."""
        U = self.layout.as_blocks(U)
        out = np.empty((self.q.n_points, len(self.part_names)))
        for a, b in self._point_ranges():
            pts = np.arange(a, b, dtype=np.int64)
            out[a:b] = self._evaluate(pts, U, 0)[0]
        return out

    def energy(self, U) -> dict[str, float]:
        """{'total', <part>: …}: Π = Σ_q w_q W(jet_q) and its parts (energy units)."""
        parts = self.q.weights @ self.densities(U)
        return {"total": float(parts.sum()), **{n: float(v) for n, v in
                                                zip(self.part_names, parts)}}

    def _point_ranges(self):
        m = self.q.n_points
        return [(a, min(a + CHUNK, m)) for a in range(0, m, CHUNK)] or [(0, 0)]

    # -- global vectors and matrices -------------------------------------------------------
    def residual(self, U, want_densities: bool = False):
        """(Π, R (n_dofs,)) or, with ``want_densities``, (Π, R, dens (m, n_parts))."""
        U = self.layout.as_blocks(U)
        q = self.q
        ranges = balanced_ranges(np.diff(q.indptr).astype(float), self._n_parts(q.n_points))
        parts = self._run(residual_part, [(U, a0, a1) for a0, a1 in split_for_cluster(ranges)],
                          "residual")
        dens = np.concatenate([d for _, d in parts]) if len(parts) > 1 else parts[0][1]
        f = parts[0][0]
        for extra, _ in parts[1:]:
            f += extra
        W = float((q.weights @ dens).sum())
        return (W, f.ravel(), dens) if want_densities else (W, f.ravel())

    def residual_range(self, U, a0: int, a1: int):
        """(f (n_nodes, B), dens (a1 − a0, n_parts)) of the quadrature points a0..a1."""
        q, L = self.q, self.layout
        f = np.zeros((L.n_nodes, L.block))
        dens = np.empty((a1 - a0, len(self.part_names)))
        for a in range(a0, a1, CHUNK):
            pts = np.arange(a, min(a + CHUNK, a1), dtype=np.int64)
            d, g, _ = self._evaluate(pts, U, 1)
            dens[pts - a0] = d
            scatter_gradient(pts, q.indptr, q.indices, q.basis, q.weights, g,
                             L.jet_column, L.jet_dof, f)
        return f, dens

    # -- where the parts run -----------------------------------------------------------------
    @staticmethod
    def _n_parts(n_items: int) -> int:
        """Parts of a residual or tangent: this process's threads (:func:`n_threads`), so a
        distributed run of as many worker threads sums the same parts in the same order."""
        return n_threads(n_items)

    def _run(self, fn, items, what: str) -> list:
        """``fn(self, item)`` for the parts: this process's threads, or tasks on the run's
        distributed executor (:mod:`pointatlas.executor`; the assembler is sent once)."""
        executor = current_executor()
        if executor.distributed and len(items) > 0:
            self.q.assembly_plan()  # computed here, sent with the assembler
            return executor.map(fn, items, shared=self, desc=f"{what} assembly",
                                shared_key=("assembler", self._shared_id, self._data_version),
                                labels=[f"{what} part {i}" for i in range(len(items))])
        return run_threads(lambda *item: fn(self, item), items)

    def tangent(self, U):
        """K = ∂²Π/∂U² as scipy CSR (n_dofs, n_dofs), symmetric."""
        plan = self.q.assembly_plan()
        B, N = self.layout.block, self.layout.n_nodes
        return bsr_matrix((self.tangent_data(U), plan.cols, plan.row_ptr),
                          shape=(B * N, B * N), blocksize=(B, B)).tocsr()

    def tangent_data(self, U) -> np.ndarray:
        """(nnz_blocks, B, B): K's node blocks on the pattern of :meth:`AtlasQuadrature.
        assembly_plan` (its ``row_ptr``, ``cols``)."""
        U = self.layout.as_blocks(U)
        plan = self.q.assembly_plan()
        B = self.layout.block
        bounds = split_for_cluster([(int(b0), int(b1)) for b0, b1 in plan.thread_bounds])
        items = [(U, b0, b1) for b0, b1 in bounds]
        if current_executor().distributed:
            parts = self._run(tangent_part, items, "tangent")
            data = np.zeros((len(plan.cols), B, B))
            for touched, blocks in parts:   # the parts' sums in order, as the threads' are
                data[touched] += blocks
        else:
            from pointatlas_atlas.chart import one_blas_thread

            with one_blas_thread():  # the point products are small: BLAS threads only contend
                parts = run_threads(lambda *item: self.tangent_range(*item), items)
            data = parts[0]
            for extra in parts[1:]:
                data += extra
        return data

    def tangent_range(self, U, b0: int, b1: int) -> np.ndarray:
        """(nnz_blocks, B, B): the tangent blocks of the point blocks b0..b1 of the plan.
        Run it with BLAS at one thread (:meth:`tangent` and :func:`tangent_part` do)."""
        q, L = self.q, self.layout
        plan = q.assembly_plan()
        B = L.block
        data = np.zeros((len(plan.cols), B, B))
        c0 = b0
        while c0 < b1:  # chunks of blocks holding about CHUNK points
            first = plan.block_ptr[c0]
            c1 = int(np.searchsorted(plan.block_ptr, first + CHUNK, side="right")) - 1
            c1 = min(max(c1, c0 + 1), b1)
            pts = plan.order[first:plan.block_ptr[c1]]
            _, _, H = self._evaluate(pts, U, 2)
            tangent_blocks(c0, c1, plan.order, plan.block_ptr, np.int64(first), q.indptr,
                           q.indices, q.basis, q.weights, H, L.jet_column, L.jet_dof,
                           *L.field_tables, int(B), int(L.jet_size), plan.row_ptr,
                           plan.cols, np.int64(L.n_nodes), data)
            c0 = c1
        return data


def split_for_cluster(ranges: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """The ranges of this process's threads, each cut in k contiguous pieces when the run's
    distributed executor has k times more threads (k = 1 otherwise, and with as many worker
    threads as local ones: the parts, and so the sums, are those of a local run; with more,
    the sums are regrouped and differ from a local run's at round-off)."""
    executor = current_executor()
    threads = getattr(executor, "n_threads", None)
    if not executor.distributed or threads is None:
        return ranges
    k = -(-int(threads()) // max(1, len(ranges)))
    if k <= 1:
        return ranges
    out = []
    for a, b in ranges:
        cuts = np.linspace(a, b, k + 1).astype(np.int64)
        out += [(int(s), int(e)) for s, e in zip(cuts[:-1], cuts[1:]) if e > s]
    return out


def residual_part(assembler: Assembler, item):
    """One part of :meth:`Assembler.residual` (a task: item = (U, a0, a1))."""
    return assembler.residual_range(*item)


def tangent_part(assembler: Assembler, item):
    """One part of :meth:`Assembler.tangent` as a task (item = (U, b0, b1)): (touched,
    blocks), the indices of the pattern blocks it touches and those blocks (what is sent
    back is the part's own rows, not the whole pattern)."""
    from pointatlas_atlas.chart import one_blas_thread

    with one_blas_thread():  # a task on a worker: its own thread sets and restores
        data = assembler.tangent_range(*item)
    touched = np.flatnonzero(np.any(data != 0.0, axis=(1, 2)))
    return touched, data[touched]
