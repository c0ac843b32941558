import numpy as np
import pytest

from pointatlas_embedders.quality import (reconstruction_error, residual_variance, stress,
                                          stress_on_pairs, trustworthiness)


def test_stress_by_hand():
    # 3 collinear points, 1 neighbour each: N(0) = {1}, N(1) = {0}, N(2) = {1}; g = 1
    X = np.array([[0.0, 0, 0], [1, 0, 0], [2.5, 0, 0]])
    Y = np.array([[0.0, 0], [2.0, 0], [3.0, 0]])
    idx = np.array([[1], [0], [1]])
    g = np.array([[1.0], [1.0], [1.5]])
    expected = 0.5 * ((2 - 1) ** 2 + (2 - 1) ** 2 + ((1 - 1.5) / 1.5) ** 2)
    assert abs(stress_on_pairs(Y, idx, g) - expected) < 1e-14
    assert abs(stress(Y, X, 1) - expected) < 1e-14


def test_scaled_plane_stress_is_known():
    rng = np.random.default_rng(0)
    Y = rng.random((200, 2))
    X = np.c_[Y, np.zeros(200)]
    # embedding 2x too large: every relative error is 1 -> E = 1/2 * N * k
    assert abs(stress(2 * Y, X, 5) - 0.5 * 200 * 5) < 1e-9
    assert trustworthiness(Y, X, 5) > 0.999
    # graph geodesics on random points zig-zag a little: small but nonzero residual variance
    assert residual_variance(Y, X, 8) < 0.02
    assert residual_variance(Y[:, ::-1] * [1, 3], X, 8) > 0.1
    assert reconstruction_error(Y, X, 8) < 1e-3
    assert reconstruction_error(rng.random((200, 2)), X, 8) > 0.05


@pytest.mark.parametrize("measure, need", [("stress", 13), ("trustworthiness", 25),
                                           ("residual_variance", 13),
                                           ("reconstruction_error", 13)])
def test_too_few_points_for_the_neighbourhood_is_an_input_error(measure, need):
    import pointatlas_embedders.quality as quality
    from pointatlas.errors import InputError

    X = np.random.default_rng(0).normal(size=(need - 1, 3))
    with pytest.raises(InputError, match=rf"{measure} with n_neighbors=12 needs at least {need} "
                                         rf"points .* got {need - 1}\. Give more points"):
        getattr(quality, measure)(X[:, :2], X, n_neighbors=12)
    X = np.random.default_rng(0).normal(size=(need, 3))
    assert np.isfinite(getattr(quality, measure)(X[:, :2], X, n_neighbors=12))
