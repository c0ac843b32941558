"""Geometrically nonlinear shells along a load path: increments, Newton, step cutting.

Thesis §4.4 / Paper 2 §4–5 and App. E.2: the total potential Π(U) = W(U) − λ FᵀU of the
geometrically exact Kirchhoff–Love energy W (St. Venant–Kirchhoff, :mod:`.nonlinear`) is
minimised at each load factor λ subject to the supports C U = λ g: loads and imposed
displacements are both scaled by λ, so a path with F = 0 and an imposed displacement is
under displacement control (the reaction of that support is then the load). Under load
(force or displacement) control each increment runs, for the target λ,

1. an optional coarse L-BFGS minimisation of the augmented Lagrangian Π_ρ
   (:meth:`.equilibrium.Equilibrium.lbfgs`, ``lbfgs_iterations`` > 0), then
2. Newton: min ½ ΔUᵀ K_T ΔU + Rᵀ ΔU subject to C ΔU = λg − C U,
   R = f_int(U) − λF + Cᵀμ, by the augmented Lagrangian of :mod:`.solver` (its multiplier
   increment updates μ), with a backtracking (Armijo) line search on Π_ρ while the residual
   is large and the step is a descent direction.

Both safeguards are off by default: on the pinched open hemisphere (``shell_open_hemisphere``,
200 points, first increment P = 20), full Newton steps converged in 8 iterations, while
energy backtracking cut the first steps to α = 1/8 and the increment did not converge in 15;
200 L-BFGS iterations left |∇Π_ρ| at ~1e5 × the load (the membrane/bending stiffness ratio
(R/h)² defeats first-order methods without a preconditioner).

With ``stable_path`` each load-controlled increment is solved by descent on Π_ρ instead
(:func:`.stable_equilibrium.minimise_to_stable`: Newton with an energy line search, on a
shifted tangent where it is indefinite), so every reported state is stable; past a limit
point or a bifurcation it is the state the shell snaps to (``Increment.snapped``).

``control='arc_length'`` follows the path by Crisfield's cylindrical arc length instead
(:mod:`.arc_length`), passing limit points and snap-backs. A step that does not converge in
``max_newton`` iterations (or produces NaN) is cut in half and retried from the last
converged increment; below ``min_step`` the run stops cleanly with the converged increments
kept and a message naming the remedies. The signs of the pivots of the factorised
K_T + ρCᵀC flag unstable equilibria (negative pivots: not a minimum); a negative count is
confirmed by Lanczos on the same factorisation (:func:`.branch_switching.
confirmed_negative_count`), since round-off can flip the sign of a tiny pivot.

Every reported increment carries the follower's state after it (:mod:`.path_state`), and
``start`` (a :class:`.path_state.PathStart`) continues a path from such a state exactly: a
resumed run reports the same increments as an uninterrupted one.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from pointatlas.errors import PointatlasError

from .path_state import PathStart, PathState, check_start, penalty_of, restore_penalty
from .stable_equilibrium import armijo_step, minimise_to_stable, snap_amplitude


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
    snapped: bool = False         # reached by a snap to a stable state (stable_path)
    state: Optional[PathState] = None   # the path follower's state after it (resume)


@dataclass
class PathSettings:
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


def follow_path(model, settings, path: PathSettings, F: np.ndarray, constraints,
                on_increment: Optional[Callable[[Increment], None]] = None, log=None,
                start: Optional[PathStart] = None) -> list[Increment]:
    """Increments from λ = 0 (or from ``start``, the increments of an interrupted run and the
    state after them) to ``path.max_load_factor``: load control (uniform steps, cut on
    failure) or arc length (``path.control``). Returns the new increments."""
    from .equilibrium import Equilibrium

    eq = Equilibrium(model, settings, F, constraints)
    if path.control == "arc_length":
        from .arc_length import follow_arc_length

        return follow_arc_length(eq, path, on_increment, log, start)
    if path.control != "load":
        raise ValueError(f"unknown control {path.control!r}: use 'load' or 'arc_length'")
    nominal = path.max_load_factor / path.n_increments
    state = check_start(start, "load")
    if state is None:
        U, lam_load, mu, step = np.zeros(eq.F.size), 0.0, np.zeros(eq.C.shape[0]), nominal
        prev = None    # (U, step) of the previous increment, for the secant predictor
    else:
        U, lam_load, mu, step = state.U.copy(), state.load_factor, state.mu.copy(), state.step
        prev = None if state.previous is None else (state.previous.copy(), state.previous_step)
        restore_penalty(eq, state)
    done: list[Increment] = []
    levels = sorted(float(x) for x in path.levels if x > lam_load)
    while lam_load < path.max_load_factor * (1 - 1e-12):
        step = min(step, path.max_load_factor - lam_load)
        # land on the tabulated levels (the comparison with a table needs no interpolation)
        ahead = [x for x in levels if lam_load * (1 + 1e-12) < x < lam_load + step]
        target = ahead[0] if ahead else lam_load + step
        if abs(target - path.max_load_factor) <= 1e-9 * abs(path.max_load_factor):
            target = path.max_load_factor   # end exactly on λ_max (no round-off drift)
        t0 = time.perf_counter()
        # secant predictor: extrapolate the last converged increment to the new load
        guess = U if prev is None else U + ((target - lam_load) / prev[1]) * (U - prev[0])
        snapped = False
        if path.stable_path:
            # descent on Π: stable states only; past a limit point, the one the shell snaps to
            result = minimise_to_stable(eq, path, guess, mu, target, log, 4 * path.max_newton,
                                        snap_amplitude(guess, U, floor=1e-3 * _size(eq)))
            if result is not None:
                *result, snapped = result
        else:
            result = load_increment(eq, path, guess, mu, target, log)
            if result is None and prev is not None:
                result = load_increment(eq, path, U, mu, target, log)
        if result is None:
            step = 0.5 * (target - lam_load)
            if log is not None:
                log.warning("increment to λ = %.5g did not converge; cutting the step to %.3g",
                            target, step)
            if step < path.min_step * nominal:
                raise PathFollowingError(
                    f"the load path stopped at λ = {lam_load:.5g}: the increment could not be "
                    f"cut below {path.min_step:g} of the nominal step and still converge (a "
                    "limit point or snap-through). The converged increments are saved. Use "
                    "smaller steps (more increments), displacement control, or arc-length "
                    "control (study.control=arc_length).")
            continue
        prev = None if snapped else (U, target - lam_load)
        U, mu, it, residuals, negative = result
        lam_load = target
        if it <= 4:  # converging easily: grow the step back towards its nominal size
            step = min(2 * step, nominal)
        done.append(make_increment(eq, U, mu, lam_load, it, residuals, negative, t0))
        done[-1].snapped = snapped
        done[-1].state = PathState(
            "load", lam_load, U.copy(), mu.copy(), step,
            previous=None if prev is None else prev[0].copy(),
            previous_step=np.nan if prev is None else prev[1], rho=penalty_of(eq))
        if on_increment is not None:
            on_increment(done[-1])
    return done


def _size(eq) -> float:
    """Size of the shell (length): the largest extent of its nodes, 1 without a model."""
    model = getattr(eq, "model", None)
    return 1.0 if model is None else float(np.ptp(model.nodes, axis=0).max())


def make_increment(eq, U, mu, lam, iterations, residuals, negative, t0) -> Increment:
    """The record of a converged state (energy split, stability, reactions)."""
    return Increment(lam, U.reshape(-1, 3).copy(), iterations, residuals,
                     eq.energy_parts(U), negative, negative == 0,
                     time.perf_counter() - t0,
                     support_reactions(eq.C, mu, eq.constraints.row_support))


def load_increment(eq, path: PathSettings, U0, mu0, lam: float, log=None):
    """Equilibrium at the load factor λ from (U0, μ0): L-BFGS stage then Newton with line
    search. (U, μ, iterations, residuals, negative pivots), or None if it did not converge."""
    from .branch_switching import confirmed_negative_count

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
            alpha, R_new, W_new = _line_search(eq, U, mu, dmu, lam, dU, R, W, R_new, W_new)
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


def _line_search(eq, U, mu_old, dmu, lam, dU, R, W, R_new, W_new, c1: float = 1e-4,
                 max_cuts: int = 5):
    """Safeguarded Armijo backtracking on Π_ρ(U + α dU; μ, λ), μ = μ_old + dμ (App. E.2):
    returns (α, R, W) at the accepted α. The full Newton step is kept when it reduces |R|,
    when dU is not a descent direction (an unstable state) or when no cut decreases Π_ρ."""
    if float(np.linalg.norm(R_new)) < float(np.linalg.norm(R)):
        return 1.0, R_new, W_new   # the full step already reduces the out-of-balance force
    step = armijo_step(eq, U, mu_old, dmu, lam, dU, R, W, c1, max_cuts, full=(R_new, W_new))
    return (1.0, R_new, W_new) if step is None else step
