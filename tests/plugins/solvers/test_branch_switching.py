"""Branch switching at a symmetric (pitchfork) bifurcation of a two-DOF model.

Π(x, y) = ½x² + ½y² − ½xy² + ¼y⁴ − λx (plus a held DOF z): the primary path y = 0, x = λ
loses stability at λ = 1 (K_yy = 1 − x); the secondary branch x = 2λ − 1, y² = 2λ − 2 is
stable (det K = 2λ − 2 > 0)."""
import numpy as np
import pytest
from scipy.sparse import csr_matrix

from pointatlas_solvers.arc_length import follow_arc_length
from pointatlas_solvers.augmented_lagrangian import ConstrainedSystem
from pointatlas_solvers.branch_switching import bifurcation_mode
from pointatlas_solvers.increment import PathSettings
from pointatlas_solvers.stability import negative_modes


class Pitchfork:
    """An EquilibriumProblem (pointatlas_solvers.equilibrium_problem) for U = (x, y, z), z
    held by one constraint row. ``backend``: the linear solver of its systems."""

    n_components, length_scale = 3, 1.0

    def __init__(self, backend: str = "superlu"):
        self.F = np.array([1.0, 0.0, 0.0])
        self.C = csr_matrix(np.array([[0.0, 0.0, 1.0]]))
        self.g = np.zeros(1)
        self.rho = None
        self.row_support = np.zeros(1, dtype=int)
        self.arc_mask = np.ones(3)
        self.backend = backend

    def residual(self, U, mu, lam):
        x, y, z = U
        W = 0.5 * x * x + 0.5 * y * y - 0.5 * x * y * y + 0.25 * y**4 + 0.5 * z * z
        f = np.array([x - 0.5 * y * y, y - x * y + y**3, z])
        return f - lam * self.F + self.C.T @ mu, W

    def energy_parts(self, U):
        W = self.residual(U, np.zeros(1), 0.0)[1]
        return {"total": W, "membrane": W, "bending": 0.0}

    def scale(self, lam, mu):
        return max(abs(lam), float(np.linalg.norm(self.C.T @ mu)), 1e-300)

    def system(self, U, shift: float = 0.0):
        x, y, _ = U
        K = csr_matrix(np.array([[1.0, -y, 0.0], [-y, 1 - x + 3 * y * y, 0.0], [0, 0, 1.0]])
                       + shift * np.eye(3))
        sys = ConstrainedSystem(K, self.C, 1e3, 1e-12, backend=self.backend)
        self.rho = sys.rho
        return sys


def path(switching: bool) -> PathSettings:
    return PathSettings(n_increments=7, max_load_factor=2.0, tol=1e-10, max_newton=20,
                        branch_switching=switching)


def test_without_switching_the_path_stays_on_the_unstable_primary_branch():
    incs = follow_arc_length(Pitchfork(), path(False))
    U = np.array([i.U.ravel() for i in incs])
    lam = np.array([i.load_factor for i in incs])
    assert lam[-1] == 2.0 and np.allclose(U[:, 1], 0.0) and np.allclose(U[:, 0], lam)
    assert all(i.stable == (i.load_factor < 1.0) for i in incs)


def test_switching_follows_the_stable_secondary_branch_to_the_end():
    incs = follow_arc_length(Pitchfork(), path(True))
    U = np.array([i.U.ravel() for i in incs])
    lam = np.array([i.load_factor for i in incs])
    # every increment is an equilibrium
    for i in incs:
        R, _ = Pitchfork().residual(i.U.ravel(), np.zeros(1), i.load_factor)
        assert np.abs(R).max() < 1e-8
    # it ends at λ = 2 on the secondary branch: x = 3, |y| = √2, stable
    assert lam[-1] == 2.0
    assert U[-1, 0] == pytest.approx(3.0, abs=1e-8)
    assert abs(U[-1, 1]) == pytest.approx(np.sqrt(2.0), abs=1e-8)
    assert incs[-1].stable
    # exactly one increment (the one that crossed λ = 1 on the primary path) is unstable
    assert sum(not i.stable for i in incs) == 1
    off = np.abs(U[:, 1]) > 1e-6
    assert np.allclose(U[off, 1] ** 2, 2 * lam[off] - 2, atol=1e-8)


def test_the_critical_mode_is_the_lateral_one_and_a_limit_point_is_not_a_bifurcation():
    eq = Pitchfork()
    system = eq.system(np.array([1.2, 0.0, 0.0]))
    vals, vecs = negative_modes(system, system.negative_pivots)
    assert vals.size == 1 and vals[0] == pytest.approx(-0.2, rel=1e-8)
    mask = np.ones(3)
    phi = bifurcation_mode(system, np.array([0.2, 0.0, 0.0]), mask)
    assert phi is not None and np.allclose(phi, [0.0, 1.0, 0.0], atol=1e-8)
    # a step along the unstable mode (as at a limit point) is no bifurcation
    assert bifurcation_mode(system, np.array([0.0, 0.2, 0.0]), mask) is None
    # a stable state has no mode to switch to
    assert bifurcation_mode(eq.system(np.array([0.5, 0.0, 0.0])), np.ones(3), mask) is None
