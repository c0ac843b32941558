"""The displacement step of the amor split: the minimiser of the convex, piecewise quadratic
split energy (:mod:`.amor_split`) at a frozen phase field, by semi-smooth Newton.

Each step is the constrained minimiser of the quadratic of the current piece (its tangent,
the supports by the augmented Lagrangian of the staggered problem), backtracked (Armijo)
when it does not lower Π; done when a step changes U by less than SPLIT_NEWTON_TOL of
max |U| (the pieces no longer change), or by less than SPLIT_NEWTON_STALL_STEP while Π
changes by less than SPLIT_STALL of itself (cycling between pieces at the kink, see the
constants). Not converged in SPLIT_NEWTON_MAX steps: refused
(:class:`.staggered.StaggeredNotConverged`).
"""
from __future__ import annotations

import numpy as np

#: cap on the Newton steps of one displacement step with the amor split (each a linear solve)
SPLIT_NEWTON_MAX = 50
#: a Newton step of the split smaller than this fraction of max |U|: converged
SPLIT_NEWTON_TOL = 1e-10
#: ... or smaller than this fraction while Π no longer decreases (relative change below
#: SPLIT_STALL): Gauss points sitting on the kink tr ε = 0 (a neutral line) make the
#: pieces cycle with steps this small, U being as converged as the energy can tell
SPLIT_NEWTON_STALL_STEP, SPLIT_STALL = 1e-5, 1e-12


def minimise_split(problem, factor, U0):
    """(U (n_dofs,), μ) of the split energy of ``problem`` (a
    :class:`.staggered.StaggeredProblem` whose degradation is set) at imposed-displacement
    ``factor``, from ``U0`` (None: 0); see the module doc."""
    from .staggered import StaggeredNotConverged

    A, f, springs = problem.assembler_u, factor * problem.F, problem.springs

    def merit(U):
        return A.energy(U)["total"] + 0.5 * U @ (springs @ U) - f @ U

    U = np.zeros(problem.layout_u.n_dofs) if U0 is None else np.asarray(U0, float).ravel()
    feasible = False
    for _ in range(SPLIT_NEWTON_MAX):
        K = A.tangent(U)
        Un, mu = problem._quadratic_solve(K, factor)
        d = Un - U
        size = np.abs(d).max() / max(np.abs(Un).max(), 1e-300)
        if size <= SPLIT_NEWTON_TOL:
            return Un, mu
        if feasible:                      # U satisfies the supports: a descent step
            m0, slope, alpha = merit(U), float((K @ U + springs @ U - f) @ d), 1.0
            while (m1 := merit(U + alpha * d)) > m0 + 1e-4 * alpha * slope and alpha > 1e-6:
                alpha *= 0.5
            if size <= SPLIT_NEWTON_STALL_STEP and abs(m0 - m1) <= SPLIT_STALL * abs(m0):
                return Un, mu
            Un = U + alpha * d
        U, feasible = Un, True
    raise StaggeredNotConverged(
        f"the displacement step of the amor split did not converge at imposed-displacement "
        f"factor {factor:.6g} in {SPLIT_NEWTON_MAX} Newton steps (max |ΔU| = "
        f"{np.abs(d).max():.3g}). Take smaller increments, or use physics.split=none.")
