"""Basis functions evaluated at many points, stored as flat CSR arrays."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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
