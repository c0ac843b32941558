"""One increment of a load path: its record, the path settings, Newton with line search.

Thesis §4.4 / Paper 2 §4–5 and App. E.2: the total potential Π(U) = W(U) − λ FᵀU of an
equilibrium problem (:mod:`.equilibrium_problem`) is minimised at each load factor λ subject
to the constraints C U = λ g: loads and imposed displacements are both scaled by λ, so a
path with F = 0 and an imposed displacement is under displacement control (the reaction of
that support is then the load). For a target λ, :func:`load_increment` runs

1. an optional coarse L-BFGS minimisation of the augmented Lagrangian Π_ρ
   (``eq.lbfgs``, ``lbfgs_iterations`` > 0), then
2. Newton: min ½ ΔUᵀ K_T ΔU + Rᵀ ΔU subject to C ΔU = λg − C U,
   R = f_int(U) − λF + Cᵀμ, by the augmented Lagrangian of :mod:`.augmented_lagrangian`
   (its multiplier increment updates μ), with a backtracking (Armijo) line search on Π_ρ
   (:func:`armijo_step`) while the residual is large and the step is a descent direction.

Both safeguards are off by default: on the pinched open hemisphere (``shell_open_hemisphere``,
200 points, first increment P = 20), full Newton steps converged in 8 iterations, while
energy backtracking cut the first steps to α = 1/8 and the increment did not converge in 15;
200 L-BFGS iterations left |∇Π_ρ| at ~1e5 × the load (the membrane/bending stiffness ratio
(R/h)² defeats first-order methods without a preconditioner).

A converged state's count of negative eigenvalues of K_T + ρCᵀC (not a minimum when > 0) is
the checked count of :func:`.stability.confirmed_negative_count`.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Optional

import numpy as np

from pointatlas.errors import PointatlasError

from .path_state import PathState
from .stability import confirmed_negative_count


def support_reactions(C, mu: np.ndarray, row_support: np.ndarray,
                      n_components: int) -> np.ndarray:
    """Resultant force (n_supports, n_components) each support exerts on the body, −Σ rows
    Cᵀμ summed over the nodes (DOF n_components·a + i is component i of node a)."""
    n = int(row_support.max()) + 1 if row_support.size else 0
    out = np.zeros((n, n_components))
    for k in range(n):
        rows = row_support == k
        out[k] = -(C[rows].T @ mu[rows]).reshape(-1, n_components).sum(axis=0)
    return out

class PathFollowingError(PointatlasError):
    """The load path could not be followed further (the converged increments are kept)."""


@dataclass
class Increment:
    """One converged increment."""

    load_factor: float
    U: np.ndarray                 # (n_nodes, n_components) nodal values (displacements)
    iterations: int
    residuals: list               # relative residual after each Newton iteration
    energy: dict                  # named energy parts (eq.energy_parts), e.g. total
    negative_pivots: int          # checked negative eigenvalues of K_T + ρCᵀC
    stable: bool
    seconds: float
    reactions: Optional[np.ndarray] = None   # (n_supports, n_components) resultant reactions
    snapped: bool = False         # reached by a snap to a stable state (stable_path)
    state: Optional[PathState] = None   # the path follower's state after it (resume)


@dataclass
class PathSettings:
    """How a path is followed (the equilibrium problem comes separately)."""

    n_increments: int = 20
    max_load_factor: float = 1.0
    max_newton: int = 12
    tol: float = 1e-8             # Newton: |R| ≤ tol·|λF| (or tol·|reactions|)
    min_step: float = 1e-2        # smallest step (fraction of the nominal one) before giving up
    control: str = "load"         # 'load' (force or displacement) or 'arc_length'
    lbfgs_iterations: int = 0     # L-BFGS iterations before Newton (0: Newton only)
    lbfgs_tol: float = 1e-2       # L-BFGS stops at |∇Π_ρ| ≤ lbfgs_tol·|load|
    line_search: bool = False     # Armijo backtracking on Π_ρ while |R| > 1e-3·|load|
    max_increments: int = 400     # arc length: give up after this many increments
    levels: tuple = ()            # also solve at these λ (where first reached, arc length)
    desired_iterations: int = 5   # arc length: Newton iterations the step size aims at
    branch_switching: bool = False  # arc length: leave the path at simple bifurcations
    max_branch_switches: int = 3
    stable_path: bool = False     # load control by descent on Π: stable states only (snaps)


def make_increment(eq, U, mu, lam, iterations, residuals, negative, t0) -> Increment:
    """The record of a converged state (energy parts, stability, reactions); ``negative``
    is the checked count of negative eigenvalues (≥ 0), so ``stable`` is negative == 0."""
    n = eq.n_components
    return Increment(lam, U.reshape(-1, n).copy(), iterations, residuals,
                     eq.energy_parts(U), negative, negative == 0,
                     time.perf_counter() - t0,
                     support_reactions(eq.C, mu, eq.row_support, n))


def load_increment(eq, path: PathSettings, U0, mu0, lam: float, log=None):
    """Equilibrium at the load factor λ from (U0, μ0): L-BFGS stage then Newton with line
    search. (U, μ, iterations, residuals, negative pivots), or None if it did not converge."""
    U, mu = U0.copy(), mu0.copy()
    if path.lbfgs_iterations > 0 and eq.rho is not None:
        U, _ = eq.lbfgs(U, mu, lam, path.lbfgs_tol, path.lbfgs_iterations, log)
    R, W = eq.residual(U, mu, lam)
    residuals = []
    for it in range(1, path.max_newton + 1):
        sys = eq.system(U)
        dU, dmu, _ = sys.solve(-R, lam * eq.g - eq.C @ U)
        if not np.all(np.isfinite(dU)):
            return None
        scale = eq.scale(lam, mu + dmu)
        alpha, (R_new, W_new) = 1.0, eq.residual(U + dU, mu + dmu, lam)
        if path.line_search and float(np.linalg.norm(R)) > 1e-3 * scale:
            alpha, R_new, W_new = line_search(eq, U, mu, dmu, lam, dU, R, W, R_new, W_new)
        U, mu, R, W = U + alpha * dU, mu + dmu, R_new, W_new
        res = float(np.linalg.norm(R)) / eq.scale(lam, mu)
        residuals.append(res)
        if log is not None:
            log.info("  λ = %.5g  Newton %d: |R|/|λF| = %.3e  |ΔU| = %.3e%s", lam, it, res,
                     float(np.abs(dU).max()), "" if alpha == 1.0 else f"  (step {alpha:.3g})")
        if not np.isfinite(res):
            return None
        small_step = float(np.abs(dU).max()) <= 1e-10 * max(float(np.abs(U).max()), 1e-300)
        if res <= path.tol or (small_step and it >= 2):
            return U, mu, it, residuals, confirmed_negative_count(sys)
    return None


def line_search(eq, U, mu_old, dmu, lam, dU, R, W, R_new, W_new, c1: float = 1e-4,
                max_cuts: int = 5):
    """Safeguarded Armijo backtracking on Π_ρ(U + α dU; μ, λ), μ = μ_old + dμ (App. E.2):
    returns (α, R, W) at the accepted α. The full Newton step is kept when it reduces |R|,
    when dU is not a descent direction (an unstable state) or when no cut decreases Π_ρ."""
    if float(np.linalg.norm(R_new)) < float(np.linalg.norm(R)):
        return 1.0, R_new, W_new   # the full step already reduces the out-of-balance force
    step = armijo_step(eq, U, mu_old, dmu, lam, dU, R, W, c1, max_cuts, full=(R_new, W_new))
    return (1.0, R_new, W_new) if step is None else step


def armijo_step(eq, U, mu_old, dmu, lam: float, dU, R, W, c1: float = 1e-4,
                max_cuts: int = 12, full=None):
    """Backtracking on Π_ρ(U + α dU; μ_old + dμ, λ), α = 1, ½, … 2^-max_cuts, until the
    Armijo decrease Π_ρ(α) ≤ Π_ρ(0) + c₁ α ∇Π_ρ·dU holds (App. E.2): (α, R, W) at the
    accepted α, or None if dU is not a descent direction or no α decreases Π_ρ enough.
    ``full``: (R, W) at α = 1 if the caller already has them."""
    mu = mu_old + dmu
    c = eq.C @ U - lam * eq.g
    grad = R + eq.C.T @ (dmu + (eq.rho or 0.0) * c)     # ∇Π_ρ(U; μ, λ)
    slope = float(grad @ dU)
    if not slope < 0:
        return None
    phi0 = eq.merit(W, U, mu, lam)
    alpha = 1.0
    for _ in range(max_cuts + 1):
        R_a, W_a = full if alpha == 1.0 and full is not None else eq.residual(U + alpha * dU,
                                                                              mu, lam)
        if eq.merit(W_a, U + alpha * dU, mu, lam) <= phi0 + c1 * alpha * slope:
            return alpha, R_a, W_a
        alpha *= 0.5
    return None
