"""Arc-length continuation (Crisfield's cylindrical method) of an equilibrium path.

Paper 2 §5 follows snap-through (pull-out cylinder) and buckling paths; under force control
Newton fails at a limit point dλ/ds = 0. Here λ is an unknown, and each increment adds the
constraint that the displacement increment of the DOFs the problem's ``arc_mask`` selects
(for a shell the surface's control points, ghost nodes excluded) has a prescribed length Δs
(Crisfield 1981, "A fast incremental/iterative solution procedure that handles
snap-through", Comput. Struct. 13:55–62, the cylindrical variant):

    |ΔU|² = Δs²,   ΔU = U − U_k.

The loads λF and the imposed displacements λg both scale with λ. Each iteration solves, with
one factorisation of K_T + ρCᵀC (:class:`.augmented_lagrangian.ConstrainedSystem`), the two
constrained problems

    K δU_R + Cᵀ δμ_R = −R,  C δU_R = λg − CU;      K δU_F + Cᵀ δμ_F = F,  C δU_F = g,

and δU = δU_R + δλ δU_F with δλ the root of a δλ² + b δλ + c = 0 (a = |δU_F|²,
b = 2 δU_F·(ΔU + δU_R), c = |ΔU + δU_R|² − Δs²) that keeps ΔU closest in direction to the
previous iterate (when there is no real root, the minimiser −b/2a of the quadratic). The
predictor follows the tangent δU_F with the sign of ΔU_prev·δU_F
(so the path continues through limit points); an increment that turns back against the
previous one (the corrector fell onto the states just left) is redone with the predictor
reversed, then with a shorter arc. Δs adapts to the Newton iterations
(×sqrt(desired/it), within [½, 2] per increment and at most Δs₀, the length of the first
increment, which is load controlled; an increment whose |Δλ| exceeds 1.5 nominal steps is
redone with a proportionally shorter arc); ``path.levels`` (tabulated load factors) are
solved exactly, by load control from the last converged state, where the path first reaches
them (the comparison with a table then needs no interpolation); a failed
increment (no real root, NaN, too many iterations) halves Δs and retries. Every reported
increment carries the state the loop goes on from (:mod:`.path_state`), so a resumed path
(``start``) continues exactly.
"""
from __future__ import annotations

import time
from typing import Optional

import numpy as np

from .branch_switching import bifurcation_mode
from .increment import (Increment, PathFollowingError, PathSettings, load_increment,
                        make_increment)
from .path_state import PathStart, PathState, check_start, penalty_of, restore_penalty
from .stability import confirmed_negative_count


def arc_increment(eq, path: PathSettings, U0, mu0, lam0: float, ds: float, dU_prev, m,
                  log=None, predictor: Optional[np.ndarray] = None, reverse: bool = False):
    """One arc-length increment of length ds from the converged (U0, μ0, λ0).

    ``m`` is the problem's ``arc_mask``. The predictor is the tangent δU_F (scaled to Δs,
    with the sign of ΔU_prev·δU_F, the opposite one if ``reverse``), or
    ``predictor`` (a direction of unit masked length, with Δλ = 0: the eigenvector
    injection of :mod:`.branch_switching`). Returns (U, μ, λ, iterations, residuals,
    negative pivots) or None if it failed."""
    if predictor is None:
        sys = eq.system(U0)
        dUF, dmuF, _ = sys.solve(eq.F, eq.g)
        nF = float(np.linalg.norm(m * dUF))
        if not (np.isfinite(nF) and nF > 0):
            return None
        sign = 1.0 if dU_prev is None or float(dU_prev @ (m * dUF)) >= 0 else -1.0
        sign = -sign if reverse else sign
        dlam = sign * ds / nF
        DU, Dmu, lam = dlam * dUF, dlam * dmuF, lam0 + dlam
    else:
        DU, Dmu, lam = ds * predictor, np.zeros_like(mu0), lam0
    residuals = []
    R, _ = eq.residual(U0 + DU, mu0 + Dmu, lam)
    for it in range(1, path.max_newton + 1):
        U = U0 + DU
        sys = eq.system(U)
        dUR, dmuR, _ = sys.solve(-R, lam * eq.g - eq.C @ U)
        dUF, dmuF, _ = sys.solve(eq.F, eq.g)
        a = float(dUF @ (m * dUF))
        w = DU + dUR
        b, c = 2.0 * float(dUF @ (m * w)), float(w @ (m * w)) - ds * ds
        disc = b * b - 4 * a * c
        if not (a > 0 and np.isfinite(disc)):
            return None
        if disc >= 0:
            roots = ((-b + np.sqrt(disc)) / (2 * a), (-b - np.sqrt(disc)) / (2 * a))
            r = max(roots, key=lambda t: float((w + t * dUF) @ (m * DU)))
        else:
            # no real root (the sphere |ΔU| = Δs is missed near a sharp turn): take the
            # point of the line closest to it, δλ = −b/2a, and let the next iterations
            # restore the constraint (Lam & Morley 1992)
            r = -b / (2 * a)
        step = dUR + r * dUF
        DU, Dmu, lam = DU + step, Dmu + dmuR + r * dmuF, lam + r
        U, mu = U0 + DU, mu0 + Dmu
        R, _ = eq.residual(U, mu, lam)
        res = float(np.linalg.norm(R)) / eq.scale(lam, mu)
        residuals.append(res)
        if log is not None:
            log.info("  arc length: λ = %.5g  Newton %d: |R|/|λF| = %.3e  |δU| = %.3e", lam,
                     it, res, float(np.abs(step).max()))
        if not np.isfinite(res):
            return None
        if res <= path.tol:
            return U, mu, lam, it, residuals, confirmed_negative_count(sys)
    return None


def turned_back(U_new, U, dU_prev, m) -> bool:
    """True if the step U → U_new points against the previous increment dU_prev (masked):
    the path is being retraced instead of followed."""
    return dU_prev is not None and float(dU_prev @ (m * (U_new - U))) < 0.0


def follow_arc_length(eq, path: PathSettings, on_increment=None, log=None,
                      start: Optional[PathStart] = None) -> list[Increment]:
    """Arc-length increments of the equilibrium problem ``eq``
    (:class:`.equilibrium_problem.EquilibriumProblem`) from λ = 0 (or from ``start``, the
    increments of an interrupted run and the state after them) until
    λ ≥ ``path.max_load_factor``; the last increment is brought back to exactly λ_max by a
    load-controlled solve. Returns the new increments."""
    nominal = path.max_load_factor / path.n_increments
    state = check_start(start, "arc_length")
    done: list[Increment] = [] if start is None else list(start.increments)
    n_before = len(done)
    # negative pivots before the first increment: none in the unloaded state
    start_negative = 0

    def report(inc: Increment, tail) -> None:
        """Record ``inc`` with the loop state the path goes on from (``tail``: the branch
        switch test and Δs adaptation still due, or None)."""
        inc.state = PathState("arc_length", lam, U.copy(), mu.copy(), ds, previous=dU_prev.copy(),
                              first_step=ds0, pending=tuple(sorted(pending)), switches=switches,
                              check_switch=bool(tail and tail[0]),
                              adapt_iterations=-1 if tail is None else int(tail[1]),
                              rho=penalty_of(eq))
        done.append(inc)
        if on_increment is not None:
            on_increment(inc)

    if state is None:
        U, lam, mu = np.zeros(eq.F.size), 0.0, np.zeros(eq.C.shape[0])
        mask = eq.arc_mask
        # the first increment is load controlled; its length |ΔU| is the arc length Δs₀ (the
        # linear predictor overestimates the response of a stiffening shell by orders of
        # magnitude, and a sphere of that radius may never meet the path)
        pending = {float(x) for x in path.levels if x > lam}
        step = min([nominal, *pending])
        while True:
            t0 = time.perf_counter()
            first = load_increment(eq, path, U, mu, lam + step, log)
            if first is not None:
                break
            step *= 0.5
            if step < path.min_step * nominal:
                raise PathFollowingError(
                    f"arc length: the first increment from λ = {lam:.5g} did not converge even "
                    f"at {step / nominal:.3g} of the nominal step. Use more increments.")
        U_new, mu_new, it, residuals, negative = first
        dU_prev = mask * (U_new - U)
        ds0 = float(np.linalg.norm(dU_prev))
        if not (np.isfinite(ds0) and ds0 > 0):
            raise PathFollowingError("arc length: the load (F, g) produces no displacement; "
                                     "give a load or an imposed displacement.")
        U, mu, lam = U_new, mu_new, lam + step
        pending = {x for x in pending if x > lam * (1 + 1e-12)}
        ds, switches, tail = ds0, 0, None
        report(make_increment(eq, U, mu, lam, it, residuals, negative, t0), tail)
    else:
        U, lam, mu = state.U.copy(), state.load_factor, state.mu.copy()
        mask = eq.arc_mask
        dU_prev, ds, ds0 = state.previous.copy(), state.step, state.first_step
        pending, switches = set(state.pending), state.switches
        tail = None if state.adapt_iterations < 0 else (state.check_switch,
                                                        state.adapt_iterations)
        restore_penalty(eq, state)
    # resumed after a tabulated level (a side solve in the middle of an arc step): the arc
    # step is redone from the state before it, without counting the level against
    # max_increments again, and the next level's solve starts from the ρ it had then
    mid_step = state is not None and start.increments[-1].load_factor != state.load_factor
    while True:
        if tail is not None:
            # after the last increment: the branch switch test, then Δs adapts to the
            # Newton iterations
            check, it = tail
            tail = None
            if check:
                t0 = time.perf_counter()
                switched = switch_branch(eq, path, U, mu, lam, ds, dU_prev, mask, log)
                if switched is not None:
                    switches += 1
                    U_new, mu_new, lam_new, it, residuals, negative = switched
                    dU_prev = mask * (U_new - U)
                    U, mu, lam = U_new, mu_new, lam_new
                    pending.difference_update(x for x in list(pending) if x <= lam)
                    tail = (False, it)
                    report(make_increment(eq, U, mu, lam, it, residuals, negative, t0), tail)
                    continue
            ds = min(ds * float(np.clip(np.sqrt(path.desired_iterations / max(it, 1)), 0.5,
                                        2.0)), ds0)
        if not lam < path.max_load_factor * (1 - 1e-12):
            break
        if len(done) >= path.max_increments and not mid_step:
            raise PathFollowingError(
                f"arc length: λ = {lam:.5g} after {len(done)} increments without reaching "
                f"λ_max = {path.max_load_factor:g}. The converged increments are saved. "
                "Raise study.max_increments or use larger steps (fewer study.n_increments).")
        t0 = time.perf_counter()
        result = arc_increment(eq, path, U, mu, lam, ds, dU_prev, mask, log)
        if result is not None and turned_back(result[0], U, dU_prev, mask):
            # the corrector went back along the path (near a tight pair of folds the sphere
            # |ΔU| = Δs also meets the states just left): retry with the predictor reversed,
            # and if that turns back too, shorten the arc
            if log is not None:
                log.warning("arc-length increment from λ = %.5g went back along the path (to "
                            "λ = %.5g); retrying with the predictor reversed", lam, result[2])
            result = arc_increment(eq, path, U, mu, lam, ds, dU_prev, mask, log, reverse=True)
            if result is not None and turned_back(result[0], U, dU_prev, mask):
                result = None
        if result is None:
            ds *= 0.5
            if log is not None:
                log.warning("arc-length increment from λ = %.5g did not converge; Δs → %.3g",
                            lam, ds)
            if ds < 0.1 * path.min_step * ds0:
                raise PathFollowingError(
                    f"arc length: the path stopped at λ = {lam:.5g}: the arc could not be cut "
                    f"below {0.1 * path.min_step:g} of the initial one and still converge (a "
                    "bifurcation or a very sharp turn). The converged increments are saved. "
                    "Use more increments or a finer point set.")
            continue
        U_new, mu_new, lam_new, it, residuals, negative = result
        if abs(lam_new - lam) > 1.5 * nominal:
            # too coarse in λ to resolve the curve (the shell stiffens): shorten the arc
            ds *= nominal / abs(lam_new - lam)
            continue
        if lam_new > path.max_load_factor * (1 - 1e-12) and lam_new != path.max_load_factor:
            # land on λ_max exactly (also when within round-off of it), from the last
            # converged state
            exact = load_increment(eq, path, U, mu, path.max_load_factor, log)
            if exact is not None:
                U_new, mu_new, it, residuals, negative = exact
                lam_new = path.max_load_factor
        if mid_step:
            restore_penalty(eq, state)
            mid_step = False
        if lam_new > lam:
            # tabulated levels first reached in (λ, λ_new]: land on them by load control
            # (side solves from the current state, which a resumed run redoes the arc from)
            for level in sorted(x for x in pending if lam < x < lam_new):
                t1 = time.perf_counter()
                exact = load_increment(eq, path, U, mu, level, log)
                pending.discard(level)
                if exact is not None:
                    report(make_increment(eq, exact[0], exact[1], level, *exact[2:], t1), None)
            pending.difference_update(x for x in list(pending) if x <= lam_new)
        rising = lam_new > lam and (len(done) < 2 or
                                    done[-1].load_factor > done[-2].load_factor)
        before = done[-1].negative_pivots if done else start_negative
        dU_prev = mask * (U_new - U)
        U, mu, lam = U_new, mu_new, lam_new
        tail = (path.branch_switching and switches < path.max_branch_switches and rising
                and negative > before >= 0, it)
        report(make_increment(eq, U, mu, lam, it, residuals, negative, t0), tail)
    return done[n_before:]


def switch_branch(eq, path: PathSettings, U, mu, lam: float, ds: float, step, mask, log=None):
    """Leave the primary path at a simple bifurcation just crossed by ``step`` (the last
    increment, which reached (U, μ, λ) with more negative pivots than before): an arc-length
    increment whose predictor is the critical eigenvector (:mod:`.branch_switching`), of
    length Δs and then 2Δs. Accepted if it converges to a state with fewer negative pivots
    (the secondary branch); otherwise None and the path goes on along the primary branch."""
    system = eq.system(U)
    count = confirmed_negative_count(system)
    phi = bifurcation_mode(system, step, mask, log=log)
    if phi is None:
        if log is not None:
            log.info("λ = %.5g: %d negative pivots, the unstable mode is along the path (a "
                     "limit point): no branch switch", lam, count)
        return None
    for length in (ds, 2.0 * ds):
        result = arc_increment(eq, path, U, mu, lam, length, None, mask, log, predictor=phi)
        if result is not None and 0 <= result[5] < count:
            if log is not None:
                log.info("λ = %.5g: bifurcation (%d negative pivots); switched to the "
                         "secondary branch at λ = %.5g (%d negative pivots)", lam, count,
                         result[2], result[5])
            return result
    if log is not None:
        log.warning("λ = %.5g: bifurcation (%d negative pivots) but the eigenvector predictor "
                    "did not reach a more stable branch; going on along the primary path",
                    lam, count)
    return None
