"""Arc length passes a snap-through that stops force control (a one-DOF spring with a
cubic force law f(u) = u − 1.5u² + 0.6u³: limit points at u = (3 ∓ √1.8)/3.6)."""
import numpy as np
import pytest
from scipy.sparse import csr_matrix

from pointatlas_solvers.arc_length import follow_arc_length
from pointatlas_solvers.augmented_lagrangian import ConstrainedSystem
from pointatlas_solvers.increment import PathSettings


def force(u):
    return u - 1.5 * u**2 + 0.6 * u**3


class CubicSpring:
    """An EquilibriumProblem (pointatlas_solvers.equilibrium_problem) for U = (u, v, w) with
    W = ∫f(u) + ½(v² + w²), v = w = 0 held by two constraint rows and a load F = (1, 0, 0)."""

    n_components, length_scale = 3, 1.0

    def __init__(self):
        self.F = np.array([1.0, 0.0, 0.0])
        self.C = csr_matrix(np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]))
        self.g = np.zeros(2)
        self.rho = None
        self.row_support = np.zeros(2, dtype=int)
        self.arc_mask = np.ones(3)

    def residual(self, U, mu, lam):
        u = U[0]
        W = u**2 / 2 - 0.5 * u**3 + 0.15 * u**4 + 0.5 * (U[1] ** 2 + U[2] ** 2)
        f = np.array([force(u), U[1], U[2]])
        return f - lam * self.F + self.C.T @ mu, W

    def energy_parts(self, U):
        W = self.residual(U, np.zeros(2), 0.0)[1]
        return {"total": W, "membrane": W, "bending": 0.0}

    def scale(self, lam, mu):
        return max(abs(lam), float(np.linalg.norm(self.C.T @ mu)), 1e-300)

    def merit(self, W, U, mu, lam):
        return W - lam * float(self.F @ U)

    def system(self, U, shift: float = 0.0):
        K = csr_matrix(np.diag([1 - 3 * U[0] + 1.8 * U[0] ** 2, 1.0, 1.0]) + shift * np.eye(3))
        sys = ConstrainedSystem(K, self.C, 1e3, 1e-12)
        self.rho = sys.rho
        return sys


def test_arc_length_passes_the_limit_points_and_reaches_the_load():
    path = PathSettings(n_increments=10, max_load_factor=1.0, tol=1e-10, max_newton=15)
    incs = follow_arc_length(CubicSpring(), path)
    lam = np.array([i.load_factor for i in incs])
    u = np.array([i.U.ravel()[0] for i in incs])
    # every converged point is on the equilibrium curve
    assert np.allclose(force(u), lam, atol=1e-9)
    # it went over the first limit point (λ = 0.201) and came down the unstable branch
    assert lam.max() == pytest.approx(1.0) and np.any(np.diff(lam) < 0)
    unstable = [i for i in incs if not i.stable]
    lower, upper = (3 - np.sqrt(1.8)) / 3.6, (3 + np.sqrt(1.8)) / 3.6
    assert unstable and all(lower < i.U.ravel()[0] < upper for i in unstable)
    assert all(i.stable for i in incs if not lower < i.U.ravel()[0] < upper)
    # and it ends at λ = 1 exactly, on the far stable branch
    assert lam[-1] == 1.0 and u[-1] > upper and force(u[-1]) == pytest.approx(1.0, abs=1e-9)


def test_tabulated_levels_are_solved_exactly_where_first_reached():
    path = PathSettings(n_increments=10, tol=1e-10, max_newton=15, levels=(0.05, 0.15, 0.5))
    incs = follow_arc_length(CubicSpring(), path)
    lam = [i.load_factor for i in incs]
    assert lam[0] == 0.05 and 0.15 in lam and 0.5 in lam
    # 0.5 is first reached after the snap-through: on the far stable branch
    at = {i.load_factor: i.U.ravel()[0] for i in incs}
    assert force(at[0.15]) == pytest.approx(0.15, abs=1e-9) and at[0.15] < 0.461
    assert force(at[0.5]) == pytest.approx(0.5, abs=1e-9) and at[0.5] > 1.206
    assert lam.index(0.5) > lam.index(0.15) + 2


def test_an_increment_that_turns_back_is_redone_not_kept(monkeypatch):
    """Near a tight pair of folds the corrector can land on the state just left (seen on the
    connected pipes); such an increment is redone (predictor reversed, then a shorter arc)."""
    from pointatlas_solvers import arc_length as AL

    real, calls = AL.arc_increment, []

    def retracing(eq, path, U0, mu0, lam0, ds, dU_prev, m, log=None, predictor=None,
                  reverse=False):
        calls.append(reverse)
        if len(calls) == 3:  # the third arc increment falls back onto the previous state
            U = U0 - dU_prev
            return U, mu0, float(force(U[0])), 3, [1e-12], 0
        return real(eq, path, U0, mu0, lam0, ds, dU_prev, m, log, predictor, reverse)

    monkeypatch.setattr(AL, "arc_increment", retracing)
    path = PathSettings(n_increments=10, max_load_factor=1.0, tol=1e-10, max_newton=15)
    incs = AL.follow_arc_length(CubicSpring(), path)
    assert calls[2:4] == [False, True]         # the turned-back one, then the reversed retry
    u = np.array([i.U.ravel()[0] for i in incs])
    assert np.all(np.diff(u) > 0)              # u grows along this path: nothing retraced
    assert incs[-1].load_factor == 1.0 and np.allclose(force(u), [i.load_factor for i in incs],
                                                       atol=1e-9)
    assert AL.turned_back(np.array([0.0, 0, 0]), np.array([1.0, 0, 0]), np.array([1.0, 0, 0]),
                          np.ones(3))
    assert not AL.turned_back(np.array([2.0, 0, 0]), np.array([1.0, 0, 0]), None, np.ones(3))
