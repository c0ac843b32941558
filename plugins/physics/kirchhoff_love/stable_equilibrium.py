"""From an unstable equilibrium to a stable one at the same load: a quasi-static snap.

Under force or displacement control a Newton increment that starts just before a limit
point or a bifurcation may converge to an unstable equilibrium (a saddle of the total
potential Π, flagged by negative eigenvalues of the constrained tangent). What the shell
does there is snap, dynamically, to a stable state at the same load; with ``stable_path``
the path follows it instead of the unstable branch (the quasi-static analogue of the
thesis' post-buckling runs, Paper 2 §5.5–5.6, where the imposed displacement grows and the
shell "undergoes several geometric instabilities").

The snap is found by descent on the augmented Lagrangian Π_ρ: perturb the saddle along its
most unstable eigenvector (shift-invert Lanczos, :func:`.branch_switching.negative_modes`),
then take Newton steps on the shifted tangent K_T + σI while K_T is indefinite, with σ
twice the magnitude of its most negative eigenvalue (a Levenberg–Marquardt-type modified
Newton step is a descent direction, Nocedal & Wright 2006 §3.4), with an Armijo line search;
once K_T is positive definite, plain Newton converges quadratically to the stable minimum.
Both signs of the perturbation are tried; the stable end state of lower Π is kept. Past a
limit point of the control, where plain Newton finds no equilibrium near the last state,
the same descent from that state (:func:`minimise_to_stable`) finds the one it snaps to.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from .branch_switching import confirmed_negative_count, negative_modes


def descend_to_stable(eq, path, U0: np.ndarray, mu0: np.ndarray, lam: float,
                      amplitude: float, log=None, max_iter: int = 60):
    """A stable equilibrium at load factor λ near the unstable one (U0, μ0).

    ``amplitude`` (length) is the largest nodal displacement of the initial perturbation
    along the unstable mode, e.g. the size of the increment that reached U0. Returns
    (U, μ, iterations, residuals, 0) like :func:`.incremental.load_increment`, or None when
    neither direction reaches a stable equilibrium in ``max_iter`` iterations."""
    system = eq.system(U0)
    vals, vecs = negative_modes(system, max(confirmed_negative_count(system), 1))
    if vals.size == 0:
        return None
    phi = vecs[:, 0] / float(np.abs(vecs[:, 0]).max())
    best, best_energy = None, np.inf
    for sign in (1.0, -1.0):
        result = minimise_to_stable(eq, path, U0 + sign * amplitude * phi, mu0, lam, log, max_iter)
        if result is None:
            continue
        W = eq.residual(result[0], result[1], lam)[1]
        energy = eq.merit(W, result[0], result[1], lam)
        if log is not None:
            log.info("  snap (perturbation %+g × mode): stable at Π = %.6g after %d "
                     "iterations", sign, energy, result[2])
        if energy < best_energy:
            best, best_energy = result, energy
    return best


def minimise_to_stable(eq, path, U: np.ndarray, mu: np.ndarray, lam: float, log=None,
                       max_iter: int = 60):
    """Modified Newton with line search on Π_ρ at load factor λ from U until a stable
    equilibrium: (U, μ, iterations, residuals, 0), or None. Also what follows the path past
    a limit point of the control, where plain Newton from the last state has nothing to
    converge to and the shell snaps."""
    U, mu = U.copy(), mu.copy()
    R, W = eq.residual(U, mu, lam)
    residuals = []
    for it in range(1, max_iter + 1):
        system = eq.system(U)
        negative = confirmed_negative_count(system)
        shift = 0.0
        if negative != 0:
            vals, _ = negative_modes(system, max(negative, 1))
            shift = 2.0 * float(-vals[0]) if vals.size else 0.0
            if shift > 0.0:
                system = eq.system(U, shift=shift)
        dU, dmu, _ = system.solve(-R, lam * eq.g - eq.C @ U)
        if not np.all(np.isfinite(dU)):
            return None
        step = _armijo(eq, U, mu, dmu, lam, dU, R, W)
        if step is None:
            return None     # no decrease of Π_ρ along dU: stuck
        alpha, R, W = step
        U, mu = U + alpha * dU, mu + dmu
        res = float(np.linalg.norm(R)) / eq.scale(lam, mu)
        residuals.append(res)
        if log is not None:
            log.info("  snap: λ = %.5g  iteration %d: |R|/|λF| = %.3e  shift %.3g  step %.3g",
                     lam, it, res, shift, alpha)
        if not np.isfinite(res):
            return None
        if res <= path.tol and shift == 0.0:
            count = confirmed_negative_count(eq.system(U))
            if count == 0:
                return U, mu, it, residuals, 0
    return None


def _armijo(eq, U, mu_old, dmu, lam: float, dU, R, W, c1: float = 1e-4, max_cuts: int = 12):
    """Backtracking on Π_ρ(U + α dU; μ_old + dμ, λ) until the Armijo decrease holds (a pure
    energy criterion: a descent must not accept a step because |R| happens to fall):
    (α, R, W) at the accepted α, or None if no α ≥ 2^-max_cuts decreases Π_ρ."""
    mu = mu_old + dmu
    c = eq.C @ U - lam * eq.g
    grad = R + eq.C.T @ (dmu + (eq.rho or 0.0) * c)     # ∇Π_ρ(U; μ, λ)
    slope = float(grad @ dU)
    phi0 = eq.merit(W, U, mu, lam)
    if not slope < 0:
        return None
    alpha = 1.0
    for _ in range(max_cuts + 1):
        R_a, W_a = eq.residual(U + alpha * dU, mu, lam)
        if eq.merit(W_a, U + alpha * dU, mu, lam) <= phi0 + c1 * alpha * slope:
            return alpha, R_a, W_a
        alpha *= 0.5
    return None


def snap_amplitude(U_new: np.ndarray, U_old: np.ndarray, floor: Optional[float] = None) -> float:
    """Perturbation size for :func:`descend_to_stable`: the increment's largest nodal
    displacement (length), or ``floor`` if that is larger."""
    step = float(np.abs(np.asarray(U_new) - np.asarray(U_old)).max())
    return max(step, floor or 0.0)
