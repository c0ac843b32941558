import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas_embedders.lle import LLE


def test_lle_unit_covariance_and_unrolls_swiss_roll(swiss_roll):
    X, P = swiss_roll
    Y = pointatlas.load_plugin("embedders", "lle")(n_neighbors=12).fit_transform(X)
    np.testing.assert_allclose(Y.T @ Y / len(Y), np.eye(2), atol=1e-6)
    # LLE is not isometric, but its coordinates are monotone-ish in the unrolled ones
    C = np.abs(np.corrcoef(np.c_[Y, P].T)[:2, 2:])
    assert C.max() > 0.9


def test_lle_errors(swiss_roll):
    X, _ = swiss_roll
    with pytest.raises(ConfigError, match="n_neighbors >= 3"):
        LLE(n_neighbors=2, n_components=2).fit(X)
    with pytest.raises(InputError, match="at least 13 points"):
        LLE(n_neighbors=12).fit(X[:12])
    with pytest.raises(InputError, match="duplicate"):
        LLE().fit(np.r_[X[:100], X[:1]])
