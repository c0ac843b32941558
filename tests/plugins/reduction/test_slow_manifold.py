"""The slow manifold of noisy points on a circular arc: fit, derivatives, projection."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import InputError
from pointatlas_reduction.slow_manifold import SlowManifold, binned_nodes


def arc(n=1500, noise=0.001, seed=0):
    rng = np.random.default_rng(seed)
    th = rng.uniform(-2.0, 2.0, n)
    return np.column_stack([np.sin(th), -np.cos(th)]) + rng.normal(0, noise, (n, 2))


@pytest.fixture(scope="module")
def manifold():
    X = arc()
    Q = pointatlas.load_plugin("embedders", "isomap")(n_components=1, n_neighbors=12
                                                       ).fit_transform(X)
    return SlowManifold(pointatlas.load_plugin("approximants", "lme")(gamma=0.8),
                        n_bins=40).fit(X, Q), Q


def test_the_manifold_is_the_circle(manifold):
    sm, Q = manifold
    assert sm.residual_ < 1.5e-3 and sm.n_unfitted_ == 0
    q = np.linspace(Q.min(), Q.max(), 50)[5:-5, None]
    X, DX, D2X = sm.evaluate(q, order=2)
    assert np.abs(np.hypot(X[:, 0], X[:, 1]) - 1).max() < 2e-3
    speed = np.linalg.norm(DX[:, :, 0], axis=1)       # Isomap is an arclength: |X'| ≈ 1
    assert np.abs(speed - 1).max() < 0.02
    # X'' points to the centre with |X''| ≈ |X'|² (curvature 1); second derivatives of a fit
    # to noisy points are noisy (±25 % here), right on average
    curv = -np.einsum("md,md->m", D2X[:, :, 0, 0], X) / speed ** 2
    assert abs(curv.mean() - 1) < 0.03 and np.abs(curv - 1).max() < 0.3


def test_projection_finds_the_closest_point(manifold):
    sm, _ = manifold
    for ang in (-1.0, 0.3, 1.4):
        x = 1.05 * np.array([np.sin(ang), -np.cos(ang)])
        q, dist = sm.project(x)
        assert dist == pytest.approx(0.05, abs=3e-3)
        y = sm.evaluate(q[None])[0]
        assert np.arctan2(y[0], -y[1]) == pytest.approx(ang, abs=3e-3)


def test_binned_nodes_average_each_cell():
    Q = np.array([[0.0], [0.1], [0.9], [1.0]])
    np.testing.assert_allclose(binned_nodes(Q, 2)[:, 0], [0.05, 0.95])


def test_an_embedding_as_large_as_the_snapshots_is_refused():
    X = arc(5)
    with pytest.raises(InputError, match="not below the number of snapshots"):
        SlowManifold(pointatlas.load_plugin("approximants", "lme")()).fit(X, np.eye(5))
