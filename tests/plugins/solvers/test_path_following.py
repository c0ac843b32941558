"""follow_path dispatches on the control and refuses an unknown one."""
import numpy as np
import pytest

from pointatlas_solvers.increment import PathSettings
from pointatlas_solvers.path_following import follow_path

from .test_arc_length import CubicSpring, force


def test_the_control_chooses_the_follower():
    """Load control jumps over the cubic spring's unstable branch; arc length follows it."""
    lower, upper = (3 - np.sqrt(1.8)) / 3.6, (3 + np.sqrt(1.8)) / 3.6
    for control, unstable in (("load", False), ("arc_length", True)):
        incs = follow_path(CubicSpring(), PathSettings(n_increments=10, tol=1e-10,
                                                       max_newton=15, control=control))
        u = np.array([i.U.ravel()[0] for i in incs])
        assert incs[-1].load_factor == pytest.approx(1.0)
        assert np.allclose(force(u), [i.load_factor for i in incs], atol=1e-9)
        assert bool(np.any((u > lower) & (u < upper))) == unstable, control


def test_an_unknown_control_is_refused():
    with pytest.raises(ValueError, match="unknown control 'displacement'"):
        follow_path(CubicSpring(), PathSettings(control="displacement"))
