import numpy as np
import pytest

from pointatlas_embedders.nlie_stress import stress_energy, stress_energy_grad, stress_hessian


@pytest.fixture
def problem():
    rng = np.random.default_rng(3)
    n, d = 12, 2
    Q = rng.normal(size=(n, d))
    pi = np.array([0, 0, 1, 2, 5, 7, 3, 10])
    pj = np.array([1, 2, 3, 9, 6, 8, 4, 11])
    g = rng.uniform(0.5, 2.0, pi.size)
    w = rng.choice([1.0, 2.0], pi.size)
    return Q, pi, pj, g, w


def _energy_by_definition(Q, pi, pj, g, w, alpha):
    r = np.linalg.norm(Q[pi] - Q[pj], axis=1)
    return 0.5 * np.sum(w * (alpha * (r / g - 1) ** 2 + (1 - alpha) * (g / r - 1) ** 2))


@pytest.mark.parametrize("alpha", [1.0, 0.9, 0.3])
def test_gradient_and_hessian_match_finite_differences(problem, alpha):
    Q, pi, pj, g, w = problem
    n, d = Q.shape
    E, G = stress_energy_grad(Q, pi, pj, g, w, alpha)
    assert abs(E - _energy_by_definition(Q, pi, pj, g, w, alpha)) < 1e-12
    assert abs(stress_energy(Q, pi, pj, g, w, alpha) - E) < 1e-12
    h = 1e-6
    Gfd = np.zeros(n * d)
    Hfd = np.zeros((n * d, n * d))
    for a in range(n * d):
        e = np.zeros(n * d)
        e[a] = h
        Qp, Qm = (Q.ravel() + e).reshape(n, d), (Q.ravel() - e).reshape(n, d)
        Gfd[a] = (stress_energy(Qp, pi, pj, g, w, alpha) - stress_energy(Qm, pi, pj, g, w, alpha)) / (2 * h)
        Hfd[:, a] = (stress_energy_grad(Qp, pi, pj, g, w, alpha)[1]
                     - stress_energy_grad(Qm, pi, pj, g, w, alpha)[1]).ravel() / (2 * h)
    np.testing.assert_allclose(G.ravel(), Gfd, atol=1e-7)
    H = stress_hessian(Q, pi, pj, g, w, alpha).toarray()
    np.testing.assert_allclose(H, Hfd, atol=1e-6)
    np.testing.assert_allclose(H, H.T, atol=1e-14)


def test_rigid_motions_are_in_the_hessian_null_space(problem):
    Q, pi, pj, g, w = problem
    H = stress_hessian(Q, pi, pj, g, w, 0.9)
    t = np.tile([1.0, 0.0], Q.shape[0])                   # translation
    rot = np.c_[-Q[:, 1], Q[:, 0]].ravel()                 # infinitesimal rotation
    G = stress_energy_grad(Q, pi, pj, g, w, 0.9)[1].ravel()
    assert np.abs(H @ t).max() < 1e-12
    # differentiating grad . (J Q) = 0 gives H (J Q) = -J^T grad, zero at equilibrium
    G2 = G.reshape(-1, 2)
    np.testing.assert_allclose(H @ rot, np.c_[-G2[:, 1], G2[:, 0]].ravel(), atol=1e-10)
