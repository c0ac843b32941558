"""Constrained linear solve K U = F subject to C U = g by an augmented Lagrangian.

Thesis App. E.2 (L3669–3700) and Paper 1 App. D: the Lagrangian
L(U, λ) = ½UᵀKU − FᵀU + λᵀ(CU − g) + ½ρ|CU − g|² is minimised in U for fixed λ, then
λ ← λ + ρ(CU − g). With K_ρ = K + ρCᵀC factorised once (any backend of
:mod:`.linear_backends`), every iteration is one back-substitution; the multiplier iteration
is accelerated by conjugate gradients on the dual problem and stops when
|CU − g| ≤ tol·max|U|. Redundant constraints (two supports sharing a corner, rotation rows
already implied by displacement rows) are harmless, unlike in a saddle-point solve with
plain multipliers. ρ is ``penalty``·mean diag K / mean diag CᵀC, so it is scale free.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import csr_matrix

from pointatlas.errors import InputError

from .linear_backends import factorize


@dataclass
class SolveInfo:
    iterations: int
    violation: float           # max |CU − g| at the end (length units)
    rho: float
    times: dict = field(default_factory=dict)
    negative_pivots: int = -1  # of K + ρCᵀC (-1: the backend gives no inertia); > 0: unstable


class ConstrainedSystem:
    """K + ρCᵀC factorised once; :meth:`solve` then gives, for any right-hand side (F, g), the
    minimiser of ½UᵀKU − FᵀU subject to CU = g and its multiplier (augmented Lagrangian).

    The solution is linear in (F, g), so path-following (arc length, :mod:`.arc_length`)
    combines two solves with one factorisation. ``backend``: :mod:`.linear_backends`;
    ``negative_pivots`` is its inertia count of K_ρ (-1 if it gives none).
    """

    def __init__(self, K: csr_matrix, C: csr_matrix, penalty: float = 1e4, tol: float = 1e-10,
                 max_iter: int = 200, backend: str = "superlu",
                 reuse: "ConstrainedSystem | None" = None):
        t0 = time.perf_counter()
        self.C, self.tol, self.max_iter = C, tol, max_iter
        # CᵀC of a reused system of the same C (a Newton iteration's) is taken over
        CtC = reuse._CtC if reuse is not None and reuse.C is C else (C.T @ C).tocsr()
        self._CtC = CtC
        scale_c = CtC.diagonal().mean() if C.shape[0] else 0.0
        self.rho = penalty * K.diagonal().mean() / scale_c if scale_c > 0 else 0.0
        self.matrix = (K + self.rho * CtC).tocsr()     # K_ρ, for eigen-analysis
        # reuse: a system that is done with (its factorisation's handle is taken over)
        self.factorization = factorize(self.matrix, backend,
                                       reuse.factorization if reuse is not None else None)
        self.backend = self.factorization.backend
        self._solve = self.factorization.solve
        self.negative_pivots = self.factorization.negative_pivots
        self.factorize_time = time.perf_counter() - t0

    def inverse(self, b: np.ndarray) -> np.ndarray:
        """K_ρ⁻¹ b with the factorisation (no constraint iteration)."""
        return self._solve(np.asarray(b, dtype=float).ravel())

    def solve(self, F: np.ndarray, g: np.ndarray):
        """(U, λ, SolveInfo) for min ½UᵀKU − FᵀU subject to CU = g."""
        t1 = time.perf_counter()
        C, rho, solve = self.C, self.rho, self._solve
        # Dual problem S λ = C U_0 − g, S = C K_ρ⁻¹ Cᵀ (symmetric positive semi-definite,
        # consistent even with redundant rows), by conjugate gradients: the multiplier update
        # of the augmented Lagrangian, accelerated; one back-substitution per iteration.
        U = solve(F + rho * (C.T @ g))
        r = C @ U - g
        lam = np.zeros(C.shape[0])
        p = r.copy()
        rr = float(r @ r)
        viol = float(np.abs(r).max(initial=0.0))
        it = 0
        while viol > self.tol * max(np.abs(U).max(), 1e-300) and it < self.max_iter and rr > 0:
            it += 1
            W = solve(C.T @ p)
            z = C @ W
            pz = float(p @ z)
            if not pz > 0:
                break
            alpha = rr / pz
            lam += alpha * p
            U -= alpha * W
            r -= alpha * z
            rr, rr_old = float(r @ r), rr
            p = r + (rr / rr_old) * p
            viol = float(np.abs(C @ U - g).max(initial=0.0))
        if not np.all(np.isfinite(U)):
            raise InputError("the solve produced NaN/inf: the problem is singular or badly "
                             "scaled. Check the supports and that the material parameters "
                             "(moduli, thickness) are positive.")
        t2 = time.perf_counter()
        # the multiplier of the augmented Lagrangian is λ + ρ(CU − g) (reactions −Cᵀμ)
        lam = lam + rho * (C @ U - g)
        return U, lam, SolveInfo(max(it, 1), viol, rho, {"factorize": self.factorize_time,
                                                         "iterate": t2 - t1},
                                 self.negative_pivots)


def solve_augmented(K: csr_matrix, F: np.ndarray, C: csr_matrix, g: np.ndarray,
                    penalty: float = 1e4, tol: float = 1e-10, max_iter: int = 200,
                    backend: str = "superlu"):
    """(U, λ, SolveInfo) for min ½UᵀKU − FᵀU subject to CU = g (augmented Lagrangian)."""
    return ConstrainedSystem(K, C, penalty, tol, max_iter, backend).solve(F, g)
