import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas_embedders.isomap import Isomap
from pointatlas_embedders.nlie import NLIE
from pointatlas_embedders.quality import stress


def test_nlie_beats_isomap_stress_on_quarter_sphere(quarter_sphere):
    X = quarter_sphere
    m = pointatlas.load_plugin("embedders", "nlie")(n_stress_neighbors=40, alpha=0.99).fit(X)
    assert m.converged_ and m.embedding_.shape == (len(X), 2)
    s_iso = stress(Isomap(n_neighbors=12).fit_transform(X), X, 12)
    s_nlie = stress(m.embedding_, X, 12)
    assert abs(s_nlie - m.stress_) < 1e-9 * s_nlie
    assert s_nlie < 0.5 * s_iso


def test_nlie_is_exact_on_a_plane():
    rng = np.random.default_rng(0)
    P = rng.random((150, 2)) * [3, 1]
    X = np.c_[P, 0.3 * P[:, 0]]          # a tilted plane: an isometric embedding exists
    # with k_G <= n_neighbors every stress pair is a graph edge, whose geodesic is Euclidean
    m = NLIE(n_neighbors=12, n_stress_neighbors=10, tol=1e-10, lbfgs_max_iter=50, aic=True).fit(X)
    assert m.stress_ < 1e-10 and m.objective_ < 1e-10


def test_nlie_errors():
    X = np.random.default_rng(0).random((55, 3))
    with pytest.raises(ConfigError, match="alpha=0"):
        NLIE(alpha=0).fit(X)
    with pytest.raises(ConfigError, match="n_stress_neighbors=60"):
        NLIE(n_stress_neighbors=60).fit(X)
    two = np.r_[X, X + 10]
    with pytest.raises(InputError, match="2 connected components"):
        NLIE(n_neighbors=5, n_stress_neighbors=10).fit(two)


def test_nlie_optimize_newton_from_distorted_seed_and_lbfgs_stage():
    from pointatlas_embedders.geodesics import geodesic_neighbors, pairs_from_neighbors
    from pointatlas_embedders.neighbor_graph import neighbor_graph
    from pointatlas_embedders.nlie import gradient_tolerance, nlie_optimize

    rng = np.random.default_rng(2)
    P = rng.random((300, 2)) * [3, 1]
    G = neighbor_graph(np.c_[P, 0.3 * P[:, 0]], 10)
    pi, pj, g, w = pairs_from_neighbors(*geodesic_neighbors(G, 30))
    Y0 = P * [1.1, 0.9] + 0.02 * rng.normal(size=P.shape)     # locally distorted, globally right
    for lbfgs in (0, 10):
        Y, info = nlie_optimize(Y0, pi, pj, g, w, 0.99, tol=1e-8, lbfgs_max_iter=lbfgs)
        assert info["converged"] and info["lbfgs_iter"] <= lbfgs
        assert info["grad_max"] <= gradient_tolerance(g, w, 300, 1e-8) == info["grad_tol"]
        assert info["newton_iter"] <= 40
    # the tilted plane is developable but graph paths are longer than straight lines: E > 0, small
    assert 0 < info["objective"] < 1e-2 * pi.size


def test_coincident_seed_points_are_moved_apart_before_the_stress_is_minimised():
    """A landmark-Isomap seed can put two points on one spot (equal geodesic distances to every
    landmark); the stress (|x_ij|/|q_ij| − 1)² is infinite there and the kernel raised
    ZeroDivisionError. Such points move by 1e-6 of the extent; the others do not move."""
    from pointatlas_embedders.nlie import separate_coincident
    from pointatlas_embedders.nlie_stress import stress_energy_grad

    rng = np.random.default_rng(3)
    Y = rng.random((40, 2))
    Y[7] = Y[3]
    Y[21] = Y[3]
    pi, pj = np.triu_indices(40, 1)
    Z = separate_coincident(Y, pi, pj, seed=5)
    assert np.array_equal(Z, separate_coincident(Y, pi, pj, seed=5))     # seeded
    moved = np.flatnonzero(np.any(Z != Y, axis=1))
    assert set(moved) <= {3, 7, 21} and len(moved) >= 2
    assert np.max(np.abs(Z - Y)) < 1e-5
    r = np.linalg.norm(Z[pi] - Z[pj], axis=1)
    assert r.min() > 1e-8
    g = np.linalg.norm(Y[pi] - Y[pj], axis=1) + 0.1
    E, G = stress_energy_grad(Z, pi.astype(np.int64), pj.astype(np.int64), g, np.ones(len(g)),
                              0.99)
    assert np.isfinite(E) and np.isfinite(G).all()
