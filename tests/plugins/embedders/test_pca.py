import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas_embedders.pca import PCA
from pointatlas_embedders.quality import stress


def _tilted_plane(n=300, seed=0):
    rng = np.random.default_rng(seed)
    uv = rng.random((n, 2)) * [3.0, 1.0]
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    return uv @ R[:2] + [1.0, -2.0, 0.5], uv


def test_pca_recovers_a_plane_isometrically():
    X, uv = _tilted_plane()
    Y = PCA(n_components=2).fit_transform(X)
    assert stress(Y, X, 12) < 1e-20
    # pairwise distances preserved exactly
    np.testing.assert_allclose(np.linalg.norm(Y[1:] - Y[0], axis=1),
                               np.linalg.norm(uv[1:] - uv[0], axis=1), rtol=1e-10)


def test_pca_via_registry_with_aic_keeps_raw():
    X, _ = _tilted_plane()
    model = pointatlas.load_plugin("embedders", "pca")(n_components=2, aic=True)
    Y = model.fit_transform(X)
    assert model.stress_ < 1e-12 and model.stress_raw_ < 1e-12
    np.testing.assert_allclose(model.aic_matrix_, np.eye(2), atol=1e-6)
    assert model.embedding_raw_.shape == Y.shape


def test_pca_errors():
    X, _ = _tilted_plane()
    with pytest.raises(ConfigError, match="n_components=3"):
        PCA(n_components=3).fit(X)
    Xbad = X.copy()
    Xbad[4, 1] = np.nan
    with pytest.raises(InputError, match="NaN"):
        PCA().fit(Xbad)
    with pytest.raises(InputError, match="duplicate"):
        PCA().fit(np.r_[X, X[:1]])
