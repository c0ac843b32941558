import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pointatlas.errors import ConfigError
from pointatlas_physics.kirchhoff_love.linear import linear_stiffness
from pointatlas_physics.kirchhoff_love.material import ShellMaterial
from pointatlas_physics.kirchhoff_love.nonlinear import (
    energy, energy_density, internal_forces, tangent_stiffness)


@pytest.fixture(scope="module")
def state(cylinder_patch):
    q, P = cylinder_patch
    rng = np.random.default_rng(3)
    U = 0.05 * rng.standard_normal((q.n_nodes, 3)) + 0.2 * np.column_stack(
        [np.zeros(len(P)), P[:, 2] ** 2, np.sin(P[:, 0])])
    return q, P, U, rng


def test_forces_are_energy_gradient(state, material):
    q, P, U, rng = state
    f = internal_forces(q, material, U)
    W = lambda V: energy(q, material, V)["total"]
    eps = 1e-6
    for d in rng.choice(3 * q.n_nodes, 12, replace=False):
        E = np.zeros(3 * q.n_nodes)
        E[d] = eps
        E = E.reshape(-1, 3)
        fd = (W(U + E) - W(U - E)) / (2 * eps)
        assert abs(fd - f.ravel()[d]) < 1e-6 * abs(f).max()


def test_tangent_is_force_jacobian(state, material):
    q, P, U, rng = state
    K = tangent_stiffness(q, material, U)
    assert abs(K - K.T).max() < 1e-12 * abs(K).max()
    eps = 1e-6
    for d in rng.choice(3 * q.n_nodes, 8, replace=False):
        E = np.zeros(3 * q.n_nodes)
        E[d] = eps
        E = E.reshape(-1, 3)
        fd = (internal_forces(q, material, U + E) - internal_forces(q, material, U - E)) / (2 * eps)
        assert abs(fd.ravel() - K[:, d].toarray().ravel()).max() < 1e-6 * abs(K).max()
    # geometric stiffness matters at this U: K_T differs from the linear K
    assert abs(K - linear_stiffness(q, material)).max() > 1e-3 * abs(K).max()


def test_finite_rigid_motion_has_zero_energy(state, material):
    q, P, U, rng = state
    R = Rotation.from_rotvec([0.4, -0.9, 0.6]).as_matrix()
    Urig = P @ R.T - P + np.array([0.3, -1.0, 2.0])
    W = energy(q, material, Urig)
    scale = energy(q, material, U)["total"]
    assert abs(W["total"]) < 1e-12 * scale
    assert abs(internal_forces(q, material, Urig)).max() < 1e-9 * abs(
        internal_forces(q, material, U)).max()


def test_uniform_membrane_stretch(flat_patch, material):
    q, P = flat_patch
    l1, l2 = 1.1, 0.95
    U = np.column_stack([(l1 - 1) * P[:, 0], (l2 - 1) * P[:, 1], np.zeros(len(P))])
    e1, e2, nu = 0.5 * (l1 ** 2 - 1), 0.5 * (l2 ** 2 - 1), material.poisson_ratio
    area = q.weights.sum()
    assert area == pytest.approx(1.0, rel=1e-12)
    expect = 0.5 * material.membrane_rigidity * (e1 ** 2 + e2 ** 2 + 2 * nu * e1 * e2)
    W = energy(q, material, U)
    assert W["membrane"] == pytest.approx(expect * area, rel=1e-10)
    assert abs(W["bending"]) < 1e-12 * W["membrane"]
    assert np.allclose(energy_density(q, material, U), expect, rtol=1e-10)


def test_cylindrical_bending_large_deflection(material, make_polynomial_plate):
    """x = (x, y, ½ c x²): b_11 = c/√(1+c²x²), ε_11 = ½c²x², integrated over the unit square:
    bending ½ D c arctan c, membrane E h c⁴ / (40 (1 − ν²))."""
    q, xi = make_polynomial_plate(order=30)
    c = 0.6
    U = np.zeros((6, 3))
    U[3, 2] = 0.5 * c
    W = energy(q, material, U)
    assert W["bending"] == pytest.approx(0.5 * material.bending_rigidity * c * np.arctan(c),
                                         rel=1e-9)
    assert W["membrane"] == pytest.approx(material.membrane_rigidity * c ** 4 / 40, rel=1e-10)


def test_bad_material_or_displacements_raise(cylinder_patch):
    q, P = cylinder_patch
    bad = ShellMaterial(young_modulus=1.0, poisson_ratio=0.7, thickness=0.1)
    with pytest.raises(ConfigError, match="poisson_ratio"):
        energy(q, bad, np.zeros((q.n_nodes, 3)))
    with pytest.raises(ConfigError, match="poisson_ratio"):
        linear_stiffness(q, bad)
    with pytest.raises(ValueError, match="shape"):
        internal_forces(q, ShellMaterial(1.0, 0.3, 0.1), np.zeros((q.n_nodes, 2)))
