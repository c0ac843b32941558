"""A path resumed from the state after any of its increments goes on exactly as the
uninterrupted path: arc length over limit points with tabulated levels, arc length with a
branch switch, load control with levels and with stable_path (the models of
test_arc_length, test_branch_switching and test_stable_equilibrium)."""
import numpy as np
import pytest

from pointatlas_solvers.arc_length import follow_arc_length
from pointatlas_solvers.increment import PathSettings
from pointatlas_solvers.path_following import follow_path
from pointatlas_solvers.path_state import PathStart

from .test_arc_length import CubicSpring
from .test_branch_switching import Pitchfork
from .test_stable_equilibrium import ShiftablePitchfork


def _same(a, b):
    assert [i.load_factor for i in a] == pytest.approx([i.load_factor for i in b], abs=1e-12)
    assert [i.iterations for i in a] == [i.iterations for i in b]
    assert [i.negative_pivots for i in a] == [i.negative_pivots for i in b]
    assert [i.snapped for i in a] == [i.snapped for i in b]
    for x, y in zip(a, b):
        np.testing.assert_allclose(x.U, y.U, rtol=0, atol=1e-12)
        np.testing.assert_allclose(x.reactions, y.reactions, rtol=0, atol=1e-12)


def _check_every_resume(run, full):
    assert len(full) >= 4 and all(i.state is not None for i in full)
    for k in range(1, len(full) + 1):
        resumed = run(PathStart(full[:k], full[k - 1].state))
        assert len(resumed) == len(full) - k, f"resumed after increment {k}"
        _same(resumed, full[k:])


def test_arc_length_with_levels_resumes_exactly_after_every_increment():
    path = PathSettings(n_increments=10, tol=1e-10, max_newton=15, levels=(0.05, 0.15, 0.5))

    def run(start=None):
        return follow_arc_length(CubicSpring(), path, start=start)

    full = run()
    lam = [i.load_factor for i in full]
    assert np.any(np.diff(lam) < 0) and 0.5 in lam   # over the limit points, on a level
    _check_every_resume(run, full)


def test_arc_length_resumes_exactly_across_a_branch_switch():
    path = PathSettings(n_increments=7, max_load_factor=2.0, tol=1e-10, max_newton=20,
                        branch_switching=True)

    def run(start=None):
        return follow_arc_length(Pitchfork(), path, start=start)

    full = run()
    assert any(i.state.switches == 1 for i in full)       # it did switch branch
    assert abs(full[-1].U.ravel()[1]) == pytest.approx(np.sqrt(2.0), rel=1e-6)
    _check_every_resume(run, full)


@pytest.mark.parametrize("model,settings", [
    (CubicSpring, dict(n_increments=10, levels=(0.05, 0.33))),
    (ShiftablePitchfork, dict(n_increments=7, max_load_factor=2.0, max_newton=20,
                              stable_path=True)),
])
def test_load_control_resumes_exactly_after_every_increment(model, settings):
    path = PathSettings(tol=1e-10, **settings)

    def run(start=None):
        return follow_path(model(), path, start=start)

    full = run()
    _check_every_resume(run, full)
