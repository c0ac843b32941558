"""Constrained linear solve K U = F subject to C U = g by an augmented Lagrangian.

Thesis App. E.2 (L3669–3700) and Paper 1 App. D: the Lagrangian
L(U, λ) = ½UᵀKU − FᵀU + λᵀ(CU − g) + ½ρ|CU − g|² is minimised in U for fixed λ, then
λ ← λ + ρ(CU − g). With K_ρ = K + ρCᵀC factorised once, every iteration is one
back-substitution; the loop stops when |CU − g| ≤ tol·max|U|. Redundant constraints (two
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


def factorize(A: csr_matrix, method: str = "direct"):
    """A function b -> A⁻¹b; ``direct``: SuperLU (COLAMD order); ``cg_ilu``: CG with ILU."""
    from scipy.sparse.linalg import LinearOperator, cg, spilu, splu

    A = csc_matrix(A)
    if method == "direct":
        try:
            lu = splu(A, permc_spec="COLAMD")
            diag = np.abs(lu.U.diagonal())
        except RuntimeError:  # SuperLU: "Factor is exactly singular"
            diag = np.zeros(1)
        if not np.all(np.isfinite(diag)) or diag.min() <= 1e-300:
            raise InputError("the constrained stiffness matrix is singular: some motion of the "
                             "shell is not prevented by the supports, or the point cloud is too "
                             "sparse for the chart support. Add supports or more points.")
        return lu.solve
    ilu = spilu(A, drop_tol=1e-5, fill_factor=20)
    M = LinearOperator(A.shape, ilu.solve)

    def solve(b):
        x, info = cg(A, b, M=M, rtol=1e-12, maxiter=5000)
        if info != 0:
            raise InputError(f"CG with incomplete LU did not converge ({info} iterations); "
                             "use physics.solver=direct.")
        return x
    return solve


def solve_augmented(K: csr_matrix, F: np.ndarray, C: csr_matrix, g: np.ndarray,
                    penalty: float = 1e4, tol: float = 1e-10, max_iter: int = 200,
                    method: str = "direct"):
    """(U, λ, SolveInfo) for min ½UᵀKU − FᵀU subject to CU = g (augmented Lagrangian)."""
    t0 = time.perf_counter()
    CtC = (C.T @ C).tocsr()
    scale_c = CtC.diagonal().mean() if C.shape[0] else 0.0
    rho = penalty * K.diagonal().mean() / scale_c if scale_c > 0 else 0.0
    solve = factorize((K + rho * CtC).tocsr(), method)
    t1 = time.perf_counter()
    lam = np.zeros(C.shape[0])
    viol = np.inf
    U = np.zeros_like(F)
    for it in range(1, max_iter + 1):
        U = solve(F - C.T @ lam + rho * (C.T @ g))
        r = C @ U - g
        viol = float(np.abs(r).max(initial=0.0))
        lam += rho * r
        if viol <= tol * max(np.abs(U).max(), 1e-300):
            break
    if not np.all(np.isfinite(U)):
        raise InputError("the solve produced NaN/inf: the problem is singular or badly scaled. "
                         "Check the supports and that moduli and thickness are positive.")
    t2 = time.perf_counter()
    return U, lam, SolveInfo(it, viol, rho, {"factorize": t1 - t0, "iterate": t2 - t1})
