"""Basis functions evaluated at many points, stored as flat CSR arrays."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def _entry_spans(indptr: np.ndarray, rows: np.ndarray) -> list | None:
    """The flat-array spans (start, stop) of the runs of consecutive ``rows``, or None when
    the rows are scattered (more than one run per 8 rows) and are better gathered."""
    cut = np.flatnonzero(np.diff(rows) != 1) + 1 if len(rows) else np.zeros(0, np.int64)
    if not len(rows) or len(cut) + 1 > max(1, len(rows) // 8):
        return None
    first, last = rows[np.r_[0, cut]], rows[np.r_[cut - 1, len(rows) - 1]]
    return list(zip(indptr[first], indptr[last + 1]))


@dataclass(frozen=True)
class BasisFunctions:
    """Values and derivatives of n basis functions at m points (sparse, CSR layout).

    The functions non-zero at point ``i`` are ``indices[indptr[i]:indptr[i+1]]``.

    Attributes
    ----------
    indptr : (m+1,) int64
    indices : (nnz,) int64 node indices
    values : (nnz,) float64, p_a(x)
    gradients : (nnz, d) float64, ∇p_a(x), or None if not requested
    hessians : (nnz, d, d) float64, ∇∇p_a(x), or None if not requested
    outside : (m,) bool, True where a point lies outside the approximant's domain
        (only when the caller asked for a flag instead of an error), or None
    """

    indptr: np.ndarray
    indices: np.ndarray
    values: np.ndarray
    gradients: np.ndarray | None = None
    hessians: np.ndarray | None = None
    outside: np.ndarray | None = None

    @property
    def n_points(self) -> int:
        return len(self.indptr) - 1

    def to_csr(self, n_nodes: int):
        """The values as a scipy CSR matrix of shape (m, n_nodes)."""
        from scipy.sparse import csr_matrix

        return csr_matrix((self.values, self.indices, self.indptr), shape=(self.n_points, n_nodes))

    def gradient_csr(self, n_nodes: int, k: int):
        """∂p_a/∂ξ_k as a scipy CSR matrix of shape (m, n_nodes)."""
        from scipy.sparse import csr_matrix

        return csr_matrix(
            (self.gradients[:, k], self.indices, self.indptr), shape=(self.n_points, n_nodes)
        )

    def take(self, rows) -> "BasisFunctions":
        """The basis at a subset of the points (``rows``: indices or a boolean mask)."""
        rows = np.asarray(rows)
        if rows.dtype == bool:
            rows = np.flatnonzero(rows)
        counts = np.diff(self.indptr)[rows]
        indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        starts = self.indptr[rows]
        # runs of consecutive rows are contiguous in the flat arrays: copied as slices (memcpy)
        # when there are few of them (a chart's kept quadrature points), else gathered
        spans = _entry_spans(self.indptr, rows)
        if spans is not None:
            def pick(a):
                return None if a is None else np.concatenate([a[s:e] for s, e in spans])
        else:
            flat = (np.repeat(starts - indptr[:-1], counts) + np.arange(indptr[-1])
                    ).astype(np.int64)

            def pick(a):  # np.take: 4-5x faster than a[flat] on (nnz, d[, d]) arrays
                return None if a is None else np.take(a, flat, axis=0)

        return BasisFunctions(
            indptr=indptr, indices=pick(self.indices), values=pick(self.values),
            gradients=pick(self.gradients), hessians=pick(self.hessians),
            outside=None if self.outside is None else self.outside[rows])

    def compacted(self, rows) -> "BasisFunctions":
        """:meth:`take` of strictly increasing ``rows`` that reuses this basis's arrays: the
        kept entries are moved to the front in place, so this basis must not be used
        afterwards (a chart's basis at its candidate quadrature points, of which it keeps
        most: no second copy of the values and derivatives is allocated). Scattered rows
        (more than one run per 8 rows) are taken instead; arrays of which less than half
        is kept are copied, so the dropped part is freed."""
        rows = np.asarray(rows, dtype=np.int64)
        if len(rows) and (np.diff(rows) <= 0).any():
            raise ValueError("compacted: rows must be strictly increasing")
        spans = _entry_spans(self.indptr, rows)
        arrays = (self.indices, self.values, self.gradients, self.hessians)
        if spans is None or not all(a is None or a.flags.writeable for a in arrays):
            return self.take(rows)
        nnz = int(sum(e - s for s, e in spans))
        keep_views = 2 * nnz >= self.indptr[-1]

        def move(a):
            if a is None:
                return None
            d = 0
            for s, e in spans:   # d <= s: each run moves towards the front (memmove)
                if d != s:
                    a[d:d + e - s] = a[s:e]
                d += e - s
            return a[:nnz] if keep_views else a[:nnz].copy()

        counts = np.diff(self.indptr)[rows]
        return BasisFunctions(
            indptr=np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
            indices=move(self.indices), values=move(self.values),
            gradients=move(self.gradients), hessians=move(self.hessians),
            outside=None if self.outside is None else self.outside[rows])

    def renumbered(self, node_index) -> "BasisFunctions":
        """The same basis with node indices mapped through ``node_index`` (local -> global)."""
        return BasisFunctions(
            indptr=self.indptr, indices=np.asarray(node_index, dtype=np.int64)[self.indices],
            values=self.values, gradients=self.gradients, hessians=self.hessians,
            outside=self.outside)
