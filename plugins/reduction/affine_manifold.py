"""The linear (PCA) reduction as a manifold: X(q) = x̄ + Pᵀ q (thesis §5, the reference
method), with DX = Pᵀ and D²X = 0, so that the same reduced Lagrangian and variational
integrator serve both the linear and the nonlinear reductions. P (d, D): orthonormal
principal directions (rows), x̄ (D,) the snapshots' mean; q = P (x − x̄) is the projection."""
from __future__ import annotations

import numpy as np


class AffineManifold:
    is_affine = True

    def __init__(self, mean, components):
        self.mean = np.asarray(mean, dtype=np.float64)
        self.P = np.atleast_2d(np.asarray(components, dtype=np.float64))

    @property
    def dim(self) -> int:
        return self.P.shape[0]

    def evaluate(self, q, order: int = 0):
        q = np.atleast_2d(np.asarray(q, dtype=np.float64))
        X = self.mean + q @ self.P
        if not order:
            return X
        m, (d, D) = len(q), self.P.shape
        DX = np.broadcast_to(self.P.T, (m, D, d))
        out = (X, DX)
        if order >= 2:
            out += (np.zeros((m, D, d, d)),)
        return out

    def project(self, x):
        """(q, distance) of x (D,) to the affine subspace."""
        q = self.P @ (np.asarray(x, float) - self.mean)
        return q, float(np.linalg.norm(self.mean + q @ self.P - x))
