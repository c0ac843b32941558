"""Quadratic minimisation under box bounds and linear equality constraints.

    min ½ Uᵀ K U − Fᵀ U   subject to   C U = g,   l ≤ U ≤ c,

with K symmetric positive definite (on the null space of C).

* The equalities by the augmented Lagrangian (thesis App. E.2): K_ρ = K + ρCᵀC,
  F_ρ = F − Cᵀλ + ρCᵀg, λ ← λ + ρ(CU − g) until |CU − g| ≤ tol·max|U|; ρ is
  ``penalty`` × mean diag K / mean diag CᵀC, as in :mod:`.augmented_lagrangian`.
* Each inner problem min ½UᵀK_ρU − F_ρᵀU, l ≤ U ≤ c by Bertsekas' projected Newton method
  (SIAM J. Control Optim. 20 (1982) 221–246): with the gradient r = K_ρU − F_ρ and
  ε = min(ε₀, |U − P(U − r)|), the bounds held are 𝒜 = {i : U_i ≥ c_i − ε, r_i < 0} ∪
  {i : U_i ≤ l_i + ε, r_i > 0}; the step is Newton's on the free set 𝕀 (K_𝕀𝕀 d_𝕀 = −r_𝕀,
  one sparse factorisation) and a scaled gradient step on 𝒜, along the projection arc
  U(α) = P(U + αd), P the clip to [l, c], with an
  Armijo line search. It converges from any start for SPD K_ρ (unlike the primal–dual
  active-set method, which cycles when K is not an M-matrix, as LME stiffness matrices are
  not) and, once 𝒜 is identified, in one Newton step.

On return l ≤ U ≤ c holds exactly (U = P(·)), not to a tolerance; the projected gradient
is below ``tol`` relative to max(|F_ρ|, |K_ρ||U|) (the size of the terms the gradient sums,
whose round-off sets the floor). A cap (``max_iter``) that is reached raises rather
than returning a point that is not a minimiser.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix

from pointatlas.errors import InputError, PointatlasError

from .linear_backends import factorize


@dataclass
class BoundSolveInfo:
    iterations: int            # projected-Newton iterations, summed over the AL loop
    n_active: int              # bounds held with equality at the solution
    violation: float           # max |CU − g| at the end
    multiplier_updates: int    # augmented-Lagrangian iterations


def solve_bounded(K: csr_matrix, F: np.ndarray, C: csr_matrix, g: np.ndarray,
                  upper: np.ndarray, *, penalty: float = 1e2, tol: float = 1e-10,
                  backend: str = "superlu", max_iter: int = 200, start=None, lower=None):
    """(U, BoundSolveInfo) of min ½UᵀKU − FᵀU, CU = g, ``lower`` ≤ U ≤ ``upper`` (module
    doc; ``lower`` None: no lower bound). ``start``: a first guess (default: ``upper``, e.g.
    the previous increment's field)."""
    K = csr_matrix(K)
    C = csr_matrix(C) if C is not None else csr_matrix((0, K.shape[0]))
    F = np.asarray(F, dtype=np.float64).ravel()
    g = np.asarray(g, dtype=np.float64).ravel()
    c = np.asarray(upper, dtype=np.float64).ravel()
    n = K.shape[0]
    lo = (np.full(n, -np.inf) if lower is None
          else np.broadcast_to(np.asarray(lower, dtype=np.float64), c.shape).ravel())
    if F.shape != (n,) or c.shape != (n,) or C.shape[1] != n or g.shape != (C.shape[0],):
        raise InputError(f"solve_bounded: K is {K.shape}, F {F.shape}, upper {c.shape}, "
                         f"C {C.shape}, g {g.shape}: they must agree on {n} unknowns.")
    if np.any(lo > c):
        raise InputError(f"solve_bounded: the lower bound exceeds the upper one at "
                         f"{int((lo > c).sum())} unknown(s): no point satisfies both.")
    CtC = (C.T @ C).tocsr()
    dc = CtC.diagonal().mean() if C.shape[0] else 0.0
    rho = penalty * K.diagonal().mean() / dc if dc > 0 else 0.0
    Kr = (K + rho * CtC).tocsr() if rho else K
    lam = np.zeros(C.shape[0])
    U = np.clip(c if start is None else np.asarray(start, dtype=np.float64).ravel(), lo, c)
    total = 0
    for outer in range(1, max_iter + 1):
        Fr = F - C.T @ lam + rho * (C.T @ g)
        U, its = _projected_newton(Kr, Fr, lo, c, U, tol, backend, max_iter)
        total += its
        r = C @ U - g
        viol = float(np.abs(r).max(initial=0.0))
        if viol <= tol * max(float(np.abs(U).max()), 1e-300):
            return U, BoundSolveInfo(total, int(((U == c) | (U == lo)).sum()), viol, outer)
        lam = lam + rho * r
    raise PointatlasError(f"solve_bounded: the equality constraints were not met in {max_iter} "
                          f"multiplier updates (violation {viol:.3g}): they may contradict the "
                          "bounds. Check the constraints, or raise the penalty.")


def _projected_newton(K, F, lo, c, U, tol, backend, max_iter, sigma=1e-4, eps0=1e-6):
    """(U, iterations): min ½UᵀKU − FᵀU subject to lo ≤ U ≤ c from the feasible start U.

    The Armijo test uses the exact decrease of the quadratic, Δq = rᵀδ + ½δᵀKδ for the
    step δ, which has no cancellation (q(U + δ) − q(U) in floating point loses it all near
    the minimiser). ε₀ is relative to max(1, max|c|)."""
    diag = np.maximum(K.diagonal(), 1e-300)
    absK = abs(K)
    eps0 = eps0 * max(1.0, float(np.abs(c).max(initial=0.0)))
    has_lo = bool(np.isfinite(lo).any())
    for it in range(1, max_iter + 1):
        r = K @ U - F
        pg = U - np.clip(U - r / diag, lo, c)     # scaled projected gradient (units of U)
        # relative to the size of the terms r sums (its round-off is ~1e-16 of it)
        scale = max(float(np.abs(F).max(initial=0.0)),
                    float((absK @ np.abs(U)).max(initial=0.0)), 1e-300)
        if float(np.abs(pg * diag).max(initial=0.0)) <= tol * scale:
            return np.clip(U, lo, c), it - 1
        eps = min(eps0, float(np.abs(pg).max()))
        A = (U >= c - eps) & (r < 0)
        if has_lo:
            A |= (U <= lo + eps) & (r > 0)
        free = np.flatnonzero(~A)
        d = np.zeros_like(U)
        d[A] = -r[A] / diag[A]
        if free.size:
            d[free] = -factorize(K[free][:, free].tocsr(), backend).solve(r[free])
        alpha = 1.0
        while alpha >= 1e-12:
            delta = np.clip(U + alpha * d, lo, c) - U
            slope = float(r @ delta)
            if slope + 0.5 * float(delta @ (K @ delta)) <= sigma * slope:
                break
            alpha *= 0.5
        else:
            raise PointatlasError("solve_bounded: no descent along the projected Newton "
                                  "direction: the matrix is not positive definite.")
        U = U + delta
    raise PointatlasError(f"solve_bounded: the projected Newton iteration did not converge in "
                          f"{max_iter} iterations: the bound-constrained minimiser was not "
                          "found. Check that the matrix is positive definite.")
