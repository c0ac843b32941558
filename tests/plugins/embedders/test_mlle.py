import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas_embedders.mlle import MLLE


def test_mlle_swiss_roll_close_to_affine_image_of_unrolled(swiss_roll):
    X, P = swiss_roll
    Y = pointatlas.load_plugin("embedders", "mlle")(n_neighbors=12).fit_transform(X)
    # MLLE recovers the unrolled coordinates up to an affine map
    A = np.c_[P, np.ones(len(P))]
    coef, *_ = np.linalg.lstsq(A, Y, rcond=None)
    r2 = 1 - ((A @ coef - Y) ** 2).sum() / ((Y - Y.mean(0)) ** 2).sum()
    assert r2 > 0.97


def test_mlle_errors(swiss_roll):
    X, _ = swiss_roll
    with pytest.raises(ConfigError, match="n_components=2 is too large"):
        MLLE(n_neighbors=2).fit(X)
    Xbad = X[:100].copy()
    Xbad[7] = np.nan
    with pytest.raises(InputError, match="NaN"):
        MLLE().fit(Xbad)
