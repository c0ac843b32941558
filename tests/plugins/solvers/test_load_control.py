"""Load control along the cubic spring of test_arc_length (f(u) = u − 1.5u² + 0.6u³, limit
points at u = (3 ∓ √1.8)/3.6): minimising at each load, it snaps over the unstable branch;
a failing increment is cut and, below min_step, stops with the remedies."""
import numpy as np
import pytest

from pointatlas_solvers.increment import PathFollowingError, PathSettings
from pointatlas_solvers.load_control import follow_load_control
from pointatlas_solvers.path_following import follow_path

from .test_arc_length import CubicSpring, force


def test_force_control_jumps_over_the_unstable_branch():
    """Minimising at each load, force control snaps from the first stable branch to the far
    one (what a dynamic snap-through does) and never sees the unstable states."""
    incs = follow_path(CubicSpring(), PathSettings(n_increments=10, tol=1e-10))
    u = np.array([i.U.ravel()[0] for i in incs])
    lower, upper = (3 - np.sqrt(1.8)) / 3.6, (3 + np.sqrt(1.8)) / 3.6
    assert all(i.stable for i in incs) and not np.any((u > lower) & (u < upper))
    assert u[1] < lower < upper < u[2]  # λ = 0.2 before the limit point 0.201, 0.3 after
    assert force(u[-1]) == pytest.approx(1.0, abs=1e-9)
    landed = follow_path(CubicSpring(), PathSettings(n_increments=10, tol=1e-10,
                                                     levels=(0.05, 0.33)))
    lam = [round(i.load_factor, 12) for i in landed]
    assert lam[0] == 0.05 and 0.33 in lam and lam[-1] == 1.0
    assert max(np.diff([0.0, *lam])) <= 0.1 + 1e-12


def test_a_step_that_cannot_converge_is_cut_then_stops_with_the_remedies():
    kept = []
    with pytest.raises(PathFollowingError, match="arc-length"):
        follow_load_control(CubicSpring(), PathSettings(n_increments=2, max_newton=1,
                                                         min_step=0.3, tol=1e-14),
                            on_increment=kept.append)
    assert kept == []
