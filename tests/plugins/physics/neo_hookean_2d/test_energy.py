"""The neo-Hookean energy kernels: forces = ∂V/∂x, tangent = ∂f/∂x, frame invariance,
linearisation to Hooke's law with the Lamé constants."""
import numpy as np
import pytest

from pointatlas_physics.neo_hookean_2d import energy
from pointatlas_physics.neo_hookean_2d.mesh import tapered_column

LAM, MU = 1000.0, 500.0


@pytest.fixture(scope="module")
def mesh():
    return tapered_column(n_triangles=120)


def _deformed(mesh, amplitude=2e-3, seed=0):
    rng = np.random.default_rng(seed)
    x = mesh.nodes + np.column_stack([0.05 * mesh.nodes[:, 1] ** 2, 0 * mesh.nodes[:, 1]])
    return x + amplitude * rng.standard_normal(mesh.nodes.shape)


def _kernels(mesh):
    G, area = energy.reference_gradients(mesh.nodes, mesh.triangles)
    return mesh.triangles, G, area, LAM, MU


def test_forces_are_the_gradient_of_the_energy(mesh):
    args = _kernels(mesh)
    x = _deformed(mesh)
    f = np.empty_like(x)
    assert energy.internal_forces(x, *args, f) > 0
    h = 1e-6
    fd = np.empty_like(x)
    for a in range(mesh.n_nodes):
        for i in range(2):
            xp, xm = x.copy(), x.copy()
            xp[a, i] += h
            xm[a, i] -= h
            fd[a, i] = (energy.elastic_energy(xp, *args)
                        - energy.elastic_energy(xm, *args)) / (2 * h)
    assert np.abs(fd - f).max() < 1e-6 * np.abs(f).max()


def test_tangent_is_the_derivative_of_the_forces(mesh):
    args = _kernels(mesh)
    x = _deformed(mesh)
    K = energy.tangent_stiffness(x, *args)
    assert abs(K - K.T).max() < 1e-10 * abs(K).max()
    rng = np.random.default_rng(1)
    h = 1e-6
    fp, fm = np.empty_like(x), np.empty_like(x)
    for _ in range(3):
        d = rng.standard_normal(x.shape)
        energy.internal_forces(x + h * d, *args, fp)
        energy.internal_forces(x - h * d, *args, fm)
        Kd = K @ d.ravel()
        assert np.abs((fp - fm).ravel() / (2 * h) - Kd).max() < 1e-6 * np.abs(Kd).max()


def test_a_rigid_motion_stores_no_energy_and_makes_no_force(mesh):
    args = _kernels(mesh)
    th = 0.9
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    x = mesh.nodes @ R.T + np.array([3.0, -2.0])
    f = np.empty_like(x)
    energy.internal_forces(x, *args, f)
    assert abs(energy.elastic_energy(x, *args)) < 1e-12
    scale = MU * np.sqrt(mesh.areas.mean())            # force of a unit strain on one triangle
    assert np.abs(f).max() < 1e-11 * scale
    # and the energy of a stretch is not zero (the check can fail)
    assert energy.elastic_energy(1.01 * x, *args) > 1e-3 * MU * mesh.areas.sum() * 1e-4


def test_a_homogeneous_deformation_has_the_closed_form_energy(mesh):
    """W(F) = μ/2 (I₁ − 2 − 2 ln J) + λ/2 (ln J)² for an affine map, total = W · area."""
    F = np.array([[1.1, 0.2], [-0.05, 0.9]])
    x = mesh.nodes @ F.T
    J, I1 = np.linalg.det(F), np.sum(F * F)
    W = 0.5 * MU * (I1 - 2 - 2 * np.log(J)) + 0.5 * LAM * np.log(J) ** 2
    assert energy.elastic_energy(x, *_kernels(mesh)) == pytest.approx(W * mesh.areas.sum(),
                                                                     rel=1e-12)


def test_the_tangent_at_rest_is_hookes_law_with_the_lame_constants(mesh):
    """uᵀ K(X) u = ∫ (2μ ε:ε + λ (tr ε)²) dA for an affine u = H X (plane strain)."""
    H = np.array([[0.3, -0.4], [0.1, 0.2]])
    u = mesh.nodes @ H.T
    K = energy.tangent_stiffness(mesh.nodes, *_kernels(mesh))
    eps = 0.5 * (H + H.T)
    expected = (2 * MU * np.sum(eps * eps) + LAM * np.trace(eps) ** 2) * mesh.areas.sum()
    assert u.ravel() @ (K @ u.ravel()) == pytest.approx(expected, rel=1e-12)


def test_an_inverted_triangle_has_infinite_energy(mesh):
    args = _kernels(mesh)
    x = mesh.nodes.copy()
    x[:, 0] *= -1                                         # a reflection: J = −1 everywhere
    assert energy.elastic_energy(x, *args) == np.inf
    assert energy.internal_forces(x, *args, np.empty_like(x)) < 0
