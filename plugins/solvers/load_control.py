"""Load (force or displacement) control along a path: uniform steps, cut on failure.

Thesis §4.4 / Paper 2 §4–5: the load factor λ goes from 0 to ``path.max_load_factor`` in
``path.n_increments`` nominal steps, landing exactly on the tabulated ``path.levels``; each
increment is solved from a secant predictor by :func:`.increment.load_increment` (Newton),
or, with ``stable_path``, by descent on Π_ρ (:func:`.stable_equilibrium.
minimise_to_stable`), so every reported state is stable; past a limit point or a
bifurcation it is the state the body snaps to (``Increment.snapped``). A step that does not
converge in ``max_newton`` iterations (or produces NaN) is cut in half and retried from the
last converged increment; below ``min_step`` the run stops cleanly with the converged
increments kept and a message naming the remedies. Easy increments (≤ 4 iterations) grow
the step back towards its nominal size.

Every reported increment carries the follower's state after it (:mod:`.path_state`), and
``start`` (a :class:`.path_state.PathStart`) continues a path from such a state exactly: a
resumed run reports the same increments as an uninterrupted one.
"""
from __future__ import annotations

import time
from typing import Callable, Optional

import numpy as np

from .increment import (Increment, PathFollowingError, PathSettings, load_increment,
                        make_increment)
from .path_state import PathStart, PathState, check_start, penalty_of, restore_penalty
from .stable_equilibrium import minimise_to_stable, snap_amplitude


def follow_load_control(eq, path: PathSettings,
                        on_increment: Optional[Callable[[Increment], None]] = None, log=None,
                        start: Optional[PathStart] = None) -> list[Increment]:
    """Load-controlled increments of the equilibrium problem ``eq``
    (:class:`.equilibrium_problem.EquilibriumProblem`) from λ = 0 (or from ``start``, the
    increments of an interrupted run and the state after them) to ``path.max_load_factor``
    (module doc). ``on_increment`` is called with each new increment. Returns the new
    increments."""
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
                                        snap_amplitude(guess, U, floor=1e-3 * eq.length_scale))
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
