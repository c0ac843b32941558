import numpy as np

from pointatlas_reduction.affine_manifold import AffineManifold


def test_affine_manifold_maps_and_projects():
    rng = np.random.default_rng(0)
    P = np.linalg.qr(rng.normal(size=(5, 2)))[0].T          # orthonormal rows
    m = AffineManifold(rng.normal(size=5), P)
    q = rng.normal(size=(3, 2))
    X, DX, D2X = m.evaluate(q, order=2)
    np.testing.assert_allclose(X, m.mean + q @ P)
    assert DX.shape == (3, 5, 2) and not D2X.any()
    q1, dist = m.project(X[1])
    np.testing.assert_allclose(q1, q[1], atol=1e-12)
    assert dist < 1e-12
