"""Quasi-static snaps under load control: the pitchfork of test_branch_switching, whose
primary path x = λ, y = 0 is unstable past λ = 1 while the branches x = 2λ − 1,
y² = 2λ − 2 are stable."""
import numpy as np
import pytest
from scipy.sparse import csr_matrix

from pointatlas_solvers.increment import PathSettings
from pointatlas_solvers.path_following import follow_path
from pointatlas_solvers.stable_equilibrium import minimise_to_stable, snap_amplitude

from .test_branch_switching import Pitchfork


class ShiftablePitchfork(Pitchfork):
    """Adds what the descent needs: Π_ρ with its constraint terms."""

    def merit(self, W, U, mu, lam):
        c = self.C @ U - lam * self.g
        return W - lam * float(self.F @ U) + float(mu @ c) + 0.5 * (self.rho or 0) * float(c @ c)


def run(stable_path: bool):
    path = PathSettings(n_increments=7, max_load_factor=2.0, tol=1e-10, max_newton=20,
                        stable_path=stable_path)
    return follow_path(ShiftablePitchfork(), path)


def test_without_stable_path_load_control_stays_on_the_unstable_branch():
    incs = run(False)
    U = np.array([i.U.ravel() for i in incs])
    assert np.allclose(U[:, 1], 0.0)
    assert [i.stable for i in incs] == [i.load_factor < 1.0 for i in incs]


def test_stable_path_snaps_onto_the_stable_branch():
    incs = run(True)
    U = np.array([i.U.ravel() for i in incs])
    lam = np.array([i.load_factor for i in incs])
    assert lam[-1] == 2.0 and all(i.stable for i in incs)
    for i in incs:   # every reported state is an equilibrium
        R, _ = ShiftablePitchfork().residual(i.U.ravel(), np.zeros(1), i.load_factor)
        assert np.abs(R).max() < 1e-8
    past = lam > 1.0
    assert np.allclose(U[past, 1] ** 2, 2 * lam[past] - 2, atol=1e-8)
    assert np.allclose(U[past, 0], 2 * lam[past] - 1, atol=1e-8)
    assert np.allclose(U[~past, 1], 0.0)
    # one branch throughout (no flip-flopping between y > 0 and y < 0)
    assert len(set(np.sign(U[past, 1]))) == 1


def test_descent_leaves_a_saddle_along_its_unstable_mode_and_lowers_the_energy():
    eq = ShiftablePitchfork()
    lam, U0, mu0 = 1.5, np.array([1.5, 0.0, 0.0]), np.zeros(1)   # the saddle x = λ, y = 0
    path = PathSettings(tol=1e-12)
    assert minimise_to_stable(eq, path, U0, mu0, lam) is None   # no way off it without a kick
    U, mu, it, residuals, negative, snapped = minimise_to_stable(eq, path, U0, mu0, lam,
                                                                 amplitude=0.1)
    assert negative == 0 and snapped and residuals[-1] <= 1e-12
    assert U[0] == pytest.approx(2.0) and abs(U[1]) == pytest.approx(1.0)
    W0, W = eq.residual(U0, mu0, lam)[1], eq.residual(U, mu, lam)[1]
    assert eq.merit(W, U, mu, lam) < eq.merit(W0, U0, mu0, lam)
    assert snap_amplitude(U, U0) == pytest.approx(1.0)
    assert snap_amplitude(U0, U0, floor=0.2) == 0.2
    # from a point near a stable state it is plain Newton: full steps, no snap
    U1, *_, snapped1 = minimise_to_stable(eq, path, U + 1e-3, mu, lam)
    assert not snapped1 and np.allclose(U1, U)


def test_past_a_limit_point_the_descent_finds_the_far_stable_branch():
    """The cubic spring of test_arc_length at λ = 0.3, beyond its limit point λ = 0.201:
    from the last state before it (u = 0.3) the descent ends on the far branch."""
    from pointatlas_solvers.stable_equilibrium import minimise_to_stable

    from .test_arc_length import CubicSpring, force

    U, mu, it, residuals, negative, snapped = minimise_to_stable(
        CubicSpring(), PathSettings(tol=1e-12), np.array([0.3, 0.0, 0.0]), np.zeros(2), 0.3)
    upper = (3 + np.sqrt(1.8)) / 3.6
    assert negative == 0 and snapped and U[0] > upper
    assert force(U[0]) == pytest.approx(0.3, abs=1e-10)


def test_snapped_increments_are_flagged():
    incs = run(True)
    # only the first increment past λ = 1 snaps; Newton then follows the secondary branch
    first = next(k for k, i in enumerate(incs) if i.load_factor > 1.0)
    assert [i.snapped for i in incs] == [k == first for k in range(len(incs))]


def test_an_imposed_displacement_is_applied_before_convergence_is_declared():
    """Displacement control from rest: R = 0 there, but the support is violated."""
    from .test_arc_length import CubicSpring, force

    class ImposedSpring(CubicSpring):
        def __init__(self):
            super().__init__()
            self.F = np.zeros(3)
            self.C = csr_matrix(np.eye(3))
            self.g = np.array([1.0, 0.0, 0.0])      # u = λ, v = w = 0

        merit = ShiftablePitchfork.merit             # Π_ρ with the constraint terms

    U, mu, it, *_ = minimise_to_stable(ImposedSpring(), PathSettings(tol=1e-10), np.zeros(3),
                                       np.zeros(3), 0.3)
    assert it >= 1 and U[0] == pytest.approx(0.3, abs=1e-12)
    assert -mu[0] == pytest.approx(force(0.3), rel=1e-8)   # the reaction holds the spring
