import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas_embedders.isomap import Isomap, landmark_isomap_embedding


def _corr_best(Y, P):
    C = np.abs(np.corrcoef(np.c_[Y, P].T)[:2, 2:])
    return max(C[0, 0] + C[1, 1], C[0, 1] + C[1, 0]) / 2, C


def test_isomap_unrolls_swiss_roll_and_matches_sklearn(swiss_roll):
    from sklearn.manifold import Isomap as SkIsomap

    X, P = swiss_roll
    Y = pointatlas.load_plugin("embedders", "isomap")(n_neighbors=10, n_components=2).fit_transform(X)
    assert Y.shape == (800, 2)
    C = np.abs(np.corrcoef(np.c_[Y, P].T)[:2, 2:])
    assert C[0, 0] > 0.99 and C[1, 1] > 0.99      # first axis: arc length, second: height
    Ys = SkIsomap(n_neighbors=10, n_components=2).fit_transform(X)
    sign = np.sign(np.sum(Y * Ys, axis=0))
    assert np.abs(Y * sign - Ys).max() < 1e-8 * np.abs(Ys).max()


def test_isomap_radius_graph(swiss_roll):
    X, P = swiss_roll
    Y = Isomap(n_neighbors=None, radius=4.0).fit_transform(X)
    C = np.abs(np.corrcoef(np.c_[Y, P].T)[:2, 2:])
    assert C[0, 0] > 0.98


def test_landmark_isomap_close_to_full(swiss_roll):
    X, P = swiss_roll
    Y = landmark_isomap_embedding(X, 2, 10, n_landmarks=150)
    C = np.abs(np.corrcoef(np.c_[Y, P].T)[:2, 2:])
    assert C[0, 0] > 0.99 and C[1, 1] > 0.98


def test_isomap_errors(swiss_roll):
    X, _ = swiss_roll
    rng = np.random.default_rng(0)
    two = np.r_[rng.random((40, 3)), rng.random((25, 3)) + 50]
    with pytest.raises(InputError, match=r"2 connected components of sizes \[40, 25\]"):
        Isomap(n_neighbors=5).fit(two)
    with pytest.raises(InputError, match="n_neighbors=10 needs at least 11"):
        Isomap(n_neighbors=10).fit(X[:8])
    with pytest.raises(InputError, match="inf"):
        Isomap().fit(np.r_[X[:50], [[np.inf, 0, 0]]])
    with pytest.raises(InputError, match="duplicate"):
        Isomap().fit(np.r_[X[:50], X[3:4]])
    with pytest.raises(ConfigError, match="exactly one"):
        Isomap(n_neighbors=None, radius=None).fit(X)
    with pytest.raises(ConfigError, match="n_components=3"):
        Isomap(n_components=3).fit(X)
    with pytest.raises(ConfigError, match="n_neighbors=0"):
        Isomap(n_neighbors=0).fit(X)
