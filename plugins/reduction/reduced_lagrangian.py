"""The reduced Lagrangian on a slow manifold (thesis §5.1, Eqs. 5 and 10; Millán & Arroyo
2013, Eq. 4).

With x = X(q) the full configuration, the full Lagrangian ½ ẋᵀ M ẋ − V(x) restricted to the
manifold is L̃(q, q̇) = ½ q̇ᵀ M̃(q) q̇ − Ṽ(q) with the reduced mass and effective potential

    M̃(q) = DX(q)ᵀ M DX(q),        Ṽ(q) = V(X(q)),
    ∂M̃_ij/∂q_k = (∂_k DX_i)ᵀ M DX_j + DX_iᵀ M ∂_k DX_j,   ∂Ṽ/∂q = DXᵀ ∇V(X(q)),

DX_i the i-th column of DX (D × d), ∂_k DX_i = D²X[:, i, k]. M is the full model's mass
matrix (sparse or its diagonal); ``potential(x) -> (V, ∇V)`` its potential energy. Units:
those of M and V; q in the embedding's units.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class ReducedTerms:
    """M̃ (d, d), ∂M̃ (d, d, d) with ∂M̃[i, j, k] = ∂M̃_ij/∂q_k, Ṽ and ∂Ṽ (d,) at one q."""

    mass: np.ndarray
    mass_derivative: np.ndarray
    potential: float
    force: np.ndarray        # −∂Ṽ/∂q


class ReducedLagrangian:
    """L̃(q, q̇) of a :class:`~.slow_manifold.SlowManifold` and a full model (module doc). On an
    affine manifold (``is_affine``: DX = Pᵀ constant, D²X = 0) M̃ = P M Pᵀ is computed once and
    ∂M̃ = 0."""

    def __init__(self, manifold, mass, potential):
        self.manifold = manifold
        self.M = mass
        self.potential = potential

    def _apply_mass(self, A):
        """M A for A (D, …): M a (D,) diagonal or a (sparse) matrix."""
        M = self.M
        if np.ndim(M) == 1:
            return M.reshape((-1,) + (1,) * (A.ndim - 1)) * A
        return M @ A.reshape(A.shape[0], -1)

    def terms(self, q) -> ReducedTerms:
        q = np.asarray(q, dtype=np.float64).reshape(1, -1)
        if getattr(self.manifold, "is_affine", False):
            return self._affine_terms(q)
        X, DX, D2X = self.manifold.evaluate(q, order=2)
        x, J, H = X[0], DX[0], D2X[0]                             # (D,), (D, d), (D, d, d)
        d = J.shape[1]
        MJ = self._apply_mass(J).reshape(J.shape)
        Mt = J.T @ MJ
        dM = np.einsum("Dik,Dj->ijk", H, MJ)
        dM = dM + dM.transpose(1, 0, 2)
        V, gV = self.potential(x)
        return ReducedTerms(mass=0.5 * (Mt + Mt.T), mass_derivative=dM.reshape(d, d, d),
                            potential=float(V), force=-(J.T @ np.asarray(gV, float)))

    def _affine_terms(self, q) -> ReducedTerms:
        if getattr(self, "_affine_mass", None) is None:
            J = self.manifold.P.T                                 # (D, d)
            Mt = J.T @ self._apply_mass(J).reshape(J.shape)
            self._affine_mass = 0.5 * (Mt + Mt.T)
        d = q.shape[1]
        V, gV = self.potential(self.manifold.evaluate(q)[0])
        return ReducedTerms(mass=self._affine_mass, mass_derivative=np.zeros((d, d, d)),
                            potential=float(V),
                            force=-(self.manifold.P @ np.asarray(gV, float)))
