"""Geometrically nonlinear shells under force control: load increments, Newton, step cutting.

Thesis §4.4 / Paper 2 §4–5 and App. E.2: the total potential Π(U) = W(U) − λ FᵀU of the
geometrically exact Kirchhoff–Love energy W (St. Venant–Kirchhoff, :mod:`.nonlinear`) is
minimised at each load factor λ subject to the supports C U = λ g: loads and imposed
displacements are both scaled by λ, so a path with F = 0 and an imposed displacement is
under displacement control (the reaction of that support is then the load). Each Newton
step solves

    min ½ ΔUᵀ K_T ΔU + Rᵀ ΔU   subject to   C ΔU = λg − C U,    R = f_int(U) − λF + Cᵀμ,

by the augmented Lagrangian of :mod:`.solver` (its multiplier increment updates μ). A step
that does not converge in ``max_newton`` iterations (or produces NaN) is cut in half and
retried from the last converged increment; below ``min_step`` the run stops cleanly with the
converged increments kept and a message naming the remedies. The signs of the pivots of the
factorised K_T + ρCᵀC flag unstable equilibria (negative pivots: not a minimum).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np

from pointatlas.errors import PointatlasError


def support_reactions(C, mu: np.ndarray, row_support: np.ndarray) -> np.ndarray:
    """Resultant force (n_supports, 3) each support exerts on the shell, −Σ rows Cᵀμ."""
    n = int(row_support.max()) + 1 if row_support.size else 0
    out = np.zeros((n, 3))
    for k in range(n):
        rows = row_support == k
        out[k] = -(C[rows].T @ mu[rows]).reshape(-1, 3).sum(axis=0)
    return out


class PathFollowingError(PointatlasError):
    """The load path could not be followed further (the converged increments are kept)."""


@dataclass
class Increment:
    """One converged increment."""

    load_factor: float
    U: np.ndarray                 # (N + G, 3) nodal displacements
    iterations: int
    residuals: list               # relative residual after each Newton iteration
    energy: dict                  # total / membrane / bending
    negative_pivots: int
    stable: bool
    seconds: float
    reactions: Optional[np.ndarray] = None   # (n_supports, 3) resultant reaction forces


@dataclass
class PathSettings:
    n_increments: int = 20
    max_load_factor: float = 1.0
    max_newton: int = 12
    tol: float = 1e-8             # Newton: |R| ≤ tol·|λF| and |ΔU| ≤ tol·|U|·1e2
    min_step: float = 1e-4        # smallest load-factor increment before giving up
    history: list = field(default_factory=list)


def follow_path(model, settings, path: PathSettings, F: np.ndarray, constraints,
                on_increment: Optional[Callable[[Increment], None]] = None, log=None,
                start: Optional[Increment] = None) -> list[Increment]:
    """Increments from λ = 0 (or ``start``) to ``path.max_load_factor`` under force control."""
    from .analysis import regularize_ghosts
    from .nonlinear import energy, internal_forces, tangent_stiffness
    from .solver import solve_augmented

    q, mat = model.quadrature, model.material
    C, g = constraints.matrix, constraints.rhs
    Fv = F.ravel()
    U = np.zeros(Fv.size) if start is None else start.U.ravel().copy()
    lam_load = 0.0 if start is None else start.load_factor
    mu = np.zeros(C.shape[0])
    step = path.max_load_factor / path.n_increments
    done: list[Increment] = []
    while lam_load < path.max_load_factor * (1 - 1e-12):
        step = min(step, path.max_load_factor - lam_load)
        target = lam_load + step
        t0 = time.perf_counter()
        U_try, mu_try = U.copy(), mu.copy()
        residuals, ok, negative = [], False, -1
        scale = max(float(np.linalg.norm(target * Fv)), 1e-300)
        R = internal_forces(q, mat, U_try).ravel() - target * Fv + C.T @ mu_try
        for it in range(1, path.max_newton + 1):
            K = regularize_ghosts(tangent_stiffness(q, mat, U_try), model)
            dU, dmu, info = solve_augmented(K, -R, C, target * g - C @ U_try, settings.penalty,
                                            settings.constraint_tol, method=settings.solver)
            if not np.all(np.isfinite(dU)):
                break
            U_try += dU
            mu_try += dmu
            negative = info.negative_pivots
            # the residual after the step (also the right-hand side of the next step); its
            # scale: the applied load, or the reactions under displacement control (F = 0)
            R = internal_forces(q, mat, U_try).ravel() - target * Fv + C.T @ mu_try
            res = float(np.linalg.norm(R)) / max(scale, float(np.linalg.norm(C.T @ mu_try)))
            residuals.append(res)
            if log is not None:
                log.info("  λ = %.5g  Newton %d: |R|/|λF| = %.3e  |ΔU| = %.3e", target, it, res,
                         float(np.abs(dU).max()))
            small_step = float(np.abs(dU).max()) <= 1e-10 * max(float(np.abs(U_try).max()),
                                                                1e-300)
            if res <= path.tol or (small_step and it >= 2):
                ok = True
                break
        if not ok:
            step *= 0.5
            if log is not None:
                log.warning("increment to λ = %.5g did not converge; cutting the step to %.3g",
                            target, step)
            if step < path.min_step * path.max_load_factor:
                raise PathFollowingError(
                    f"the load path stopped at λ = {lam_load:.5g}: the increment could not be "
                    f"cut below {path.min_step:g}·λ_max and still converge (a limit point or "
                    "snap-through). The converged increments are saved. Use smaller steps "
                    "(more increments), displacement control, or arc-length control.")
            continue
        U, mu, lam_load = U_try, mu_try, target
        e = energy(q, mat, U)
        inc = Increment(lam_load, U.reshape(-1, 3).copy(), it, residuals, e, negative,
                        negative == 0, time.perf_counter() - t0,
                        support_reactions(C, mu, constraints.row_support))
        done.append(inc)
        if on_increment is not None:
            on_increment(inc)
        if it <= 4:  # converging easily: grow the step back towards its nominal size
            step = min(2 * step, path.max_load_factor / path.n_increments)
    return done
