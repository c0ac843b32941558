"""The variational integrators on an exact pendulum (the circle X(q) = (sin q, −cos q)):
period against the elliptic integral, bounded energy, momentum, the step cut, and the
tabulated 1-D path against the general one."""
import numpy as np
import pytest
from scipy.special import ellipk

from pointatlas_reduction.reduced_lagrangian import ReducedLagrangian
from pointatlas_reduction.tabulated_1d import Table1D, integrate_table
from pointatlas_reduction.variational_integrator import StepFailure, integrate


class Circle:
    """X(q) = (sin q, −cos q) with its exact derivatives (the manifold protocol)."""

    def evaluate(self, q, order=0):
        q = np.asarray(q)[:, 0]
        X = np.column_stack([np.sin(q), -np.cos(q)])
        DX = np.column_stack([np.cos(q), np.sin(q)])[:, :, None]
        D2X = np.column_stack([-np.sin(q), np.cos(q)])[:, :, None, None]
        return (X, DX, D2X)[:order + 1] if order else X


PENDULUM = ReducedLagrangian(Circle(), np.ones(2), lambda x: (x[1] + 1.0, np.array([0, 1.0])))
T90 = 4 * ellipk(0.5)


def period(t, q):
    i = np.flatnonzero((q[:-1] < 0) & (q[1:] >= 0))
    tc = t[i] - q[i] * (t[i + 1] - t[i]) / (q[i + 1] - q[i])
    return np.diff(tc).mean()


@pytest.mark.parametrize("alpha, tol", [(0.0, 1e-4), (0.5, 1e-4)])
def test_pendulum_period_at_90_degrees(alpha, tol):
    tr = integrate(PENDULUM.terms, [np.pi / 2], [0.0], T90 / 200, 800, alpha=alpha)
    assert period(tr.time, tr.q[:, 0]) == pytest.approx(T90, rel=tol)
    dev = np.abs(tr.energy - tr.energy[0])
    assert dev.max() < (0.03 if alpha == 0 else 1e-3)          # first / second order
    assert dev[-200:].max() < 1.2 * dev[:200].max()           # no drift


def test_a_free_particle_keeps_its_momentum():
    free = ReducedLagrangian(Circle(), np.ones(2), lambda x: (0.0, np.zeros(2)))
    tr = integrate(free.terms, [0.1], [0.7], 0.05, 200)
    np.testing.assert_allclose(tr.p[:, 0], 0.7, rtol=1e-10)
    np.testing.assert_allclose(np.diff(tr.q[:, 0]), 0.7 * 0.05, rtol=1e-9)


def test_a_step_newton_cannot_solve_is_cut_then_reported():
    with pytest.raises(StepFailure, match="Newton did not solve the reduced step") as e:
        integrate(PENDULUM.terms, [np.pi / 2], [0.0], 0.1, 10, max_newton=0)
    t, q, p = e.value.states
    assert len(t) == 1 and q.shape == (1, 1)


def test_the_tabulated_path_matches_the_general_one():
    tab = Table1D(PENDULUM.terms, -2.5, 2.5, 1025)
    assert tab.table_error < 1e-10
    dt = T90 / 200
    t, q, E, done = integrate_table(tab, np.pi / 2, 0.0, dt, 400)
    tr = integrate(PENDULUM.terms, [np.pi / 2], [0.0], dt, 400)
    np.testing.assert_allclose(q, tr.q[:, 0], atol=1e-7)
    np.testing.assert_allclose(E, tr.energy, atol=1e-7)


def test_leaving_the_table_is_refused():
    from pointatlas.errors import InputError

    tab = Table1D(PENDULUM.terms, -1.0, 1.0, 257)
    with pytest.raises(InputError, match="left the slow manifold's sampled region"):
        integrate_table(tab, 0.9, 1.0, 0.01, 1000)
