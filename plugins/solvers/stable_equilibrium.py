"""From an unstable equilibrium to a stable one at the same load: a quasi-static snap.

Under force or displacement control a Newton increment that starts just before a limit
point or a bifurcation may converge to an unstable equilibrium (a saddle of the total
potential Π, flagged by negative eigenvalues of the constrained tangent). What the shell
does there is snap, dynamically, to a stable state at the same load; with ``stable_path``
the path follows it instead of the unstable branch (the quasi-static analogue of the
thesis' post-buckling runs, Paper 2 §5.5–5.6, where the imposed displacement grows and the
shell "undergoes several geometric instabilities").

With ``stable_path`` every increment is solved by descent on the augmented Lagrangian Π_ρ
(:func:`minimise_to_stable`): Newton steps with an Armijo line search on Π_ρ, on the shifted
tangent K_T + σI while K_T is indefinite (σ twice the magnitude of its most negative
eigenvalue, by shift-invert Lanczos, :func:`.stability.negative_modes`; a
Levenberg–Marquardt-type modified Newton step is a descent direction, Nocedal & Wright 2006
§3.4). Near a stable solution this is plain Newton (full steps, quadratic convergence); past
a limit point, where plain Newton from the last state has nothing near to converge to, it
descends to the state the shell snaps to; a state that converges onto a saddle (a symmetric
path past a bifurcation) is pushed off along its unstable mode.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from .increment import armijo_step
from .stability import confirmed_negative_count, negative_modes

#: Relative residual below which a positive-definite tangent takes full Newton steps.
NEWTON_ZONE = 1e-3


def minimise_to_stable(eq, path, U: np.ndarray, mu: np.ndarray, lam: float, log=None,
                       max_iter: int = 60, amplitude: float = 0.0):
    """A stable equilibrium at load factor λ, by descent on Π_ρ from U: Newton steps (on
    K_T + σI while K_T is indefinite) with an Armijo line search; a state that converges
    onto a saddle (e.g. a symmetric path past a pitchfork) is left along its most unstable
    mode with nodal amplitude ``amplitude`` (length; at most twice). ``eq``: the
    :class:`.equilibrium_problem.EquilibriumProblem` (``merit`` is used).

    Returns (U, μ, iterations, residuals, 0, snapped) or None (no stable equilibrium within
    ``max_iter`` factorisations, or no descent possible). ``snapped``: reaching it needed
    more than plain Newton (a step cut by the line search, an indefinite tangent or a kick
    off a saddle), which past a limit point or a bifurcation is the shell snapping."""
    U, mu = U.copy(), mu.copy()
    R, W = eq.residual(U, mu, lam)
    residuals, snapped, kicks = [], False, 0
    # converged only if the supports hold too (an imposed displacement starts violated)
    violation = float(np.abs(eq.C @ U - lam * eq.g).max(initial=0.0))
    res = (float(np.linalg.norm(R)) / eq.scale(lam, mu)
           if violation <= 1e-12 * max(float(np.abs(U).max(initial=0.0)), 1e-300) else np.inf)
    for it in range(1, max_iter + 1):
        system = eq.system(U)
        negative = confirmed_negative_count(system)
        if res <= path.tol and negative == 0:
            return U, mu, it - 1, residuals, 0, snapped
        shift = 0.0
        if negative != 0:
            vals, vecs = negative_modes(system, max(negative, 1))
            if vals.size:
                snapped = True
                if res <= path.tol:
                    if amplitude <= 0 or kicks == 2:
                        return None   # a saddle, and no way off it
                    U = U + amplitude * vecs[:, 0] / float(np.abs(vecs[:, 0]).max())
                    R, W = eq.residual(U, mu, lam)
                    res, kicks = np.inf, kicks + 1
                    if log is not None:
                        log.info("  λ = %.5g: converged onto a saddle (%d negative "
                                 "eigenvalue(s)); leaving it along the unstable mode", lam,
                                 vals.size)
                    continue
                shift = 2.0 * float(-vals[0])
                system = eq.system(U, shift=shift)
        dU, dmu, _ = system.solve(-R, lam * eq.g - eq.C @ U)
        if not np.all(np.isfinite(dU)):
            return None
        if shift == 0.0 and res <= NEWTON_ZONE:
            # close to a stable state: full Newton steps (the energy change is at round-off
            # level there, so an energy test would only cut good steps)
            alpha, (R, W) = 1.0, eq.residual(U + dU, mu + dmu, lam)
        else:
            step = _descent_step(eq, U, mu, dmu, lam, dU, R, W)
            if step is None:
                return None     # no decrease of Π_ρ along dU: stuck
            alpha, R, W = step
        snapped = snapped or alpha < 1.0
        U, mu = U + alpha * dU, mu + dmu
        res = float(np.linalg.norm(R)) / eq.scale(lam, mu)
        residuals.append(res)
        if log is not None:
            log.info("  λ = %.5g  descent %d: |R|/|λF| = %.3e  |ΔU| = %.3e%s%s", lam, it, res,
                     float(np.abs(alpha * dU).max()), "" if alpha == 1.0 else
                     f"  (step {alpha:.3g})", "" if shift == 0.0 else f"  (shift {shift:.3g})")
        if not np.isfinite(res):
            return None
    return None


def _descent_step(eq, U, mu, dmu, lam: float, dU, R, W):
    """:func:`armijo_step` for the descent (a pure energy criterion: it must not accept a
    step because |R| happens to fall); a step the supports fix entirely (dU = 0) only
    updates the multiplier. None: stuck."""
    if float(np.abs(dU).max(initial=0.0)) <= 1e-14 * max(float(np.abs(U).max(initial=0.0)),
                                                          1e-300):
        return (1.0, *eq.residual(U + dU, mu + dmu, lam))
    return armijo_step(eq, U, mu, dmu, lam, dU, R, W)


def snap_amplitude(U_new: np.ndarray, U_old: np.ndarray, floor: Optional[float] = None) -> float:
    """Size of the kick off a saddle in :func:`minimise_to_stable`: the increment's largest nodal
    displacement (length), or ``floor`` if that is larger."""
    step = float(np.abs(np.asarray(U_new) - np.asarray(U_old)).max())
    return max(step, floor or 0.0)
