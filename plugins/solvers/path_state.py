"""The continuation state of a load path: what a path follower needs to go on exactly.

A converged increment (U, λ) alone does not determine the rest of a path: load control
(:func:`.load_control.follow_load_control`) also carries the multipliers μ of the supports (the
starting point of the next augmented-Lagrangian solve), the current step Δλ (cut on failure,
grown back after easy increments) and the secant predictor (the previous converged state and
its step); arc length (:func:`.arc_length.follow_arc_length`) carries the arc radius Δs, the
initial radius Δs₀ (its upper bound), the previous increment ΔU (the predictor's sign and the
turn-back test), the tabulated levels not yet reached, the count of branch switches and the
tests still due after the last increment (the branch switch, the adaptation of Δs to its
Newton iterations). Both use ρ, the penalty of the last factorisation, in the L-BFGS stage.

A :class:`PathState` is taken after every reported increment (``Increment.state``) at the point
where the follower's loop would go on; ``follow_path(eq, path, start=PathStart(history, state))``
(:func:`.path_following.follow_path`)
continues from it and produces the same increments as the uninterrupted run.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np


@dataclass
class PathState:
    """The follower's loop variables after a reported increment.

    U (length) and μ (force) are the state the next increment starts from: the increment's
    own for load control; for arc length, after an increment landed on a tabulated level
    (a side solve from the current state), the state before it."""

    control: str                  # 'load' or 'arc_length'
    load_factor: float            # λ of the state U
    U: np.ndarray                 # (n_dofs,) nodal displacements (length)
    mu: np.ndarray                # (n_constraints,) multipliers of C U = λ g (force)
    step: float                   # load: next Δλ; arc length: arc radius Δs (length)
    previous: Optional[np.ndarray] = None   # load: U of the previous increment (secant);
                                            # arc length: masked ΔU of the last increment
    previous_step: float = np.nan  # load: Δλ from ``previous`` to U (secant); else NaN
    first_step: float = np.nan     # arc length: Δs₀, the largest arc radius (length)
    pending: Sequence[float] = ()  # arc length: tabulated levels not yet reached
    switches: int = 0              # arc length: branch switches so far
    check_switch: bool = False     # arc length: the branch-switch test of the last increment
                                   # is still due
    adapt_iterations: int = -1     # arc length: Newton iterations Δs is still to adapt to
                                   # (-1: adapted)
    rho: float = np.nan            # penalty ρ of the last factorisation (NaN: none yet)

    SCALARS = ("load_factor", "step", "previous_step", "first_step", "switches",
               "check_switch", "adapt_iterations", "rho")


@dataclass
class PathStart:
    """Where a resumed path goes on: the increments already reported (oldest first) and the
    state after the last of them."""

    increments: list = field(default_factory=list)
    state: Optional[PathState] = None


def penalty_of(eq) -> float:
    """ρ of the equilibrium's last factorisation (NaN if none yet)."""
    rho = getattr(eq, "rho", None)
    return np.nan if rho is None else float(rho)


def restore_penalty(eq, state: PathState) -> None:
    """Give the equilibrium the ρ it had when ``state`` was taken (the L-BFGS stage of the
    next increment runs only once ρ is known)."""
    if hasattr(eq, "rho"):
        eq.rho = None if not np.isfinite(state.rho) else float(state.rho)


def check_start(start: Optional[PathStart], control: str) -> Optional[PathState]:
    """The state to go on from (None: start at λ = 0); refuses a state of the other control."""
    if start is None:
        return None
    state = start.state
    if state is None or not start.increments:
        raise ValueError("a resumed path needs the reported increments and the state after "
                         "the last of them")
    if state.control != control:
        raise ValueError(f"the saved path state is for control {state.control!r}, not "
                         f"{control!r}")
    return state
