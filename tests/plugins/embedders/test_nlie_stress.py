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


def test_pair_matvec_matches_assembled_hessian(problem):
    from pointatlas_embedders.nlie_stress import hessian_diagonal_blocks, hessian_matvec, pair_curvatures

    Q, pi, pj, g, w = problem
    H = stress_hessian(Q, pi, pj, g, w, 0.9).toarray()
    a, b = pair_curvatures(Q, pi, pj, g, w, 0.9)
    V = np.random.default_rng(1).normal(size=Q.shape)
    np.testing.assert_allclose(hessian_matvec(Q, pi, pj, a, b, V).ravel(), H @ V.ravel(),
                               atol=1e-12 * np.abs(H).max())
    D = hessian_diagonal_blocks(Q, pi, pj, a, b)
    for i in range(Q.shape[0]):
        np.testing.assert_allclose(D[i], H[2 * i:2 * i + 2, 2 * i:2 * i + 2], atol=1e-12)


def test_convex_part_is_psd_and_equals_hessian_for_stretched_pairs(problem):
    from pointatlas_embedders.nlie_stress import pair_curvatures, pair_hessian_matrix

    Q, pi, pj, g, w = problem
    Hc = pair_hessian_matrix(Q, pi, pj, *pair_curvatures(Q, pi, pj, g, w, 1.0, convex=True))
    H = stress_hessian(Q, pi, pj, g, w, 1.0).toarray()
    assert np.linalg.eigvalsh(H).min() < -1e-3            # indefinite: some pairs compressed
    assert np.linalg.eigvalsh(Hc.toarray()).min() > -1e-12
    r = np.linalg.norm(Q[pi] - Q[pj], axis=1)
    g_short = 0.5 * r                                      # every pair stretched: f', f'' > 0
    Hs = stress_hessian(Q, pi, pj, g_short, w, 1.0).toarray()
    Hcs = pair_hessian_matrix(Q, pi, pj, *pair_curvatures(Q, pi, pj, g_short, w, 1.0, convex=True))
    np.testing.assert_allclose(Hcs.toarray(), Hs, atol=1e-12)


def test_near_pairs_and_exact_preconditioner():
    from pointatlas_embedders.nlie_stress import (NearPairPreconditioner, near_pairs,
                                                  pair_curvatures, pair_hessian_matrix)

    rng = np.random.default_rng(0)
    n = 30
    Q = rng.normal(size=(n, 2))
    pi, pj = np.triu_indices(n, 1)
    g = np.linalg.norm(Q[pi] - Q[pj], axis=1) * rng.uniform(0.8, 1.2, pi.size)
    w = np.ones(pi.size)
    k = 3
    mask = near_pairs(pi, pj, g, n, k)
    D = np.full((n, n), np.inf)
    D[pi, pj] = D[pj, pi] = g
    kth = np.sort(D, axis=1)[:, k - 1]
    np.testing.assert_array_equal(mask, (g <= kth[pi]) | (g <= kth[pj]))
    # with every pair "near", M = H (+ tiny shift): M^-1 H v = v off the null space
    a, b = pair_curvatures(Q, pi, pj, g, w, 0.99, convex=True)
    H = pair_hessian_matrix(Q, pi, pj, a, b)
    M = NearPairPreconditioner(Q, pi, pj, a, b, np.ones(pi.size, bool), H.diagonal().sum(),
                               shift_rel=1e-12)
    v = rng.normal(size=2 * n)
    v -= np.tile(v.reshape(n, 2).mean(axis=0), n)          # no translation component
    Hv = H @ v
    np.testing.assert_allclose(H @ M(Hv), Hv, atol=1e-8 * np.abs(Hv).max())
