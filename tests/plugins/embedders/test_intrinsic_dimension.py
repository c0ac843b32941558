import numpy as np

from pointatlas_embedders.intrinsic_dimension import (correlation_dimension, local_pca_dimension,
                                                      local_pca_residual_variance,
                                                      pca_reconstruction_error)


def test_correlation_dimension_of_a_square_is_two_at_intermediate_scales():
    rng = np.random.default_rng(0)
    X = np.c_[rng.random((4000, 2)), np.zeros(4000)]
    eps, C, dc = correlation_dimension(X, scales=np.geomspace(0.03, 0.1, 6))
    assert np.all(np.diff(C) > 0)
    # boundary effects lower the slope slightly: d_corr = 2 - O(eps)
    assert abs(dc.mean() - 2.0) < 0.15
    # a line segment: dimension 1
    t = np.c_[rng.random(2000), np.zeros((2000, 2))]
    assert abs(correlation_dimension(t, scales=np.geomspace(0.005, 0.02, 5))[2].mean() - 1) < 0.1
    # at scales beyond the diameter every pair counts: d_corr -> 0
    assert abs(correlation_dimension(X, scales=[3.0, 4.0])[2]).max() < 1e-12


def test_local_pca_finds_two_dimensions_on_swiss_roll(swiss_roll):
    X, _ = swiss_roll
    dims, mean, pct = local_pca_residual_variance(X, n_window=15)
    assert dims.tolist() == [1, 2, 3] and pct.shape == (2, 3)
    assert mean[0] > 0.2 and mean[1] < 0.05 and abs(mean[2]) < 1e-12
    assert np.median(local_pca_dimension(X, 15, 0.95)) == 2


def test_pca_reconstruction_error_eq1_vanishes_at_full_dimension(swiss_roll):
    X, _ = swiss_roll
    dims, mean, pct = pca_reconstruction_error(X)
    assert mean[-1] < 1e-12 and mean[0] > mean[1] > mean[2]
    # a plane through the origin: zero error at d = 2
    Xp = np.c_[X[:, :2], np.zeros(len(X))]
    assert pca_reconstruction_error(Xp, dims=[2])[1][0] < 1e-12
