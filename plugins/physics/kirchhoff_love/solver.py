"""Constrained linear solve K U = F subject to C U = g by an augmented Lagrangian.

Thesis App. E.2 (L3669–3700) and Paper 1 App. D: the Lagrangian
L(U, λ) = ½UᵀKU − FᵀU + λᵀ(CU − g) + ½ρ|CU − g|² is minimised in U for fixed λ, then
λ ← λ + ρ(CU − g). With K_ρ = K + ρCᵀC factorised once, every iteration is one
back-substitution; the multiplier iteration is accelerated by conjugate gradients on the dual problem and
stops when |CU − g| ≤ tol·max|U|. Redundant constraints (two
supports sharing a corner, rotation rows already implied by displacement rows) are harmless,
unlike in a saddle-point solve with plain multipliers. ρ is ``penalty``·mean diag K /
mean diag CᵀC, so it is scale free.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import csc_matrix, csr_matrix

from pointatlas.errors import InputError


@dataclass
class SolveInfo:
    iterations: int
    violation: float           # max |CU − g| at the end (length units)
    rho: float
    times: dict = field(default_factory=dict)
    negative_pivots: int = -1  # of K + ρCᵀC (direct solver): > 0 means an unstable state


def factorize(A: csr_matrix, method: str = "direct"):
    """A function b -> A⁻¹b; ``direct``: SuperLU (symmetric mode, minimum degree on AᵀA+A);
    ``cg_ilu``: CG with an incomplete-LU preconditioner."""
    from scipy.sparse.linalg import LinearOperator, cg, spilu, splu

    A = csc_matrix(A)
    if method == "direct":
        try:
            # K + ρCᵀC is symmetric positive definite: symmetric ordering, no pivoting
            # (2–3× faster than COLAMD with partial pivoting on shell stiffness matrices)
            lu = splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                      options={"SymmetricMode": True})
            diag = np.abs(lu.U.diagonal())
        except RuntimeError:  # SuperLU: "Factor is exactly singular"
            diag = np.zeros(1)
        if not np.all(np.isfinite(diag)) or diag.min() <= 1e-300:
            raise InputError("the constrained stiffness matrix is singular: some motion of the "
                             "shell is not prevented by the supports, or the point cloud is too "
                             "sparse for the chart support. Add supports or more points.")

        def direct(b):
            return lu.solve(b)
        # without pivoting, the signs of U's diagonal are those of D in A = LDLᵀ (inertia)
        direct.negative_pivots = int((lu.U.diagonal() < 0).sum())
        return direct
    ilu = spilu(A, drop_tol=1e-5, fill_factor=20)
    M = LinearOperator(A.shape, ilu.solve)

    def solve(b):
        x, info = cg(A, b, M=M, rtol=1e-12, maxiter=2000)
        if info != 0:
            raise InputError(f"CG with incomplete LU did not converge ({info} iterations); "
                             "use physics.solver=direct.")
        return x
    return solve


class ConstrainedSystem:
    """K + ρCᵀC factorised once; :meth:`solve` then gives, for any right-hand side (F, g), the
    minimiser of ½UᵀKU − FᵀU subject to CU = g and its multiplier (augmented Lagrangian).

    The solution is linear in (F, g), so path-following (arc length, :mod:`.arc_length`)
    combines two solves with one factorisation.
    """

    def __init__(self, K: csr_matrix, C: csr_matrix, penalty: float = 1e4, tol: float = 1e-10,
                 max_iter: int = 200, method: str = "direct"):
        t0 = time.perf_counter()
        self.C, self.tol, self.max_iter = C, tol, max_iter
        CtC = (C.T @ C).tocsr()
        scale_c = CtC.diagonal().mean() if C.shape[0] else 0.0
        self.rho = penalty * K.diagonal().mean() / scale_c if scale_c > 0 else 0.0
        self.matrix = (K + self.rho * CtC).tocsr()     # K_ρ, for eigen-analysis
        self._solve = factorize(self.matrix, method)
        self.negative_pivots = getattr(self._solve, "negative_pivots", -1)
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
                             "scaled. Check the supports and that moduli and thickness are "
                             "positive.")
        t2 = time.perf_counter()
        # the multiplier of the augmented Lagrangian is λ + ρ(CU − g) (reactions −Cᵀμ)
        lam = lam + rho * (C @ U - g)
        return U, lam, SolveInfo(max(it, 1), viol, rho, {"factorize": self.factorize_time,
                                                         "iterate": t2 - t1},
                                 self.negative_pivots)


def solve_augmented(K: csr_matrix, F: np.ndarray, C: csr_matrix, g: np.ndarray,
                    penalty: float = 1e4, tol: float = 1e-10, max_iter: int = 200,
                    method: str = "direct"):
    """(U, λ, SolveInfo) for min ½UᵀKU − FᵀU subject to CU = g (augmented Lagrangian)."""
    return ConstrainedSystem(K, C, penalty, tol, max_iter, method).solve(F, g)
