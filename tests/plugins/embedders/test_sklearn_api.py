"""The embedders are scikit-learn estimators: ``check_estimator``, conventions, ``transform``."""
import re
import warnings

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.exceptions import NotFittedError
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.utils.estimator_checks import check_estimator

from pointatlas.errors import ConfigError, InputError
from pointatlas_embedders.isomap import Isomap
from pointatlas_embedders.lle import LLE
from pointatlas_embedders.mlle import MLLE
from pointatlas_embedders.nlie import NLIE
from pointatlas_embedders.pca import PCA

from .conftest import make_swiss_roll

# n_components=1: several checks fit 2-D data. n_neighbors=15: the checks' two-blob set (15 + 15
# points, far apart) then gives a connected graph (each point has a neighbour in the other blob),
# so the transformer checks (fit_transform vs transform, pickle, pipelines, dtypes) run.
K = 15
INSTANCES = {
    "pca": PCA(n_components=1),
    "isomap": Isomap(n_components=1, n_neighbors=K),
    "lle": LLE(n_components=1, n_neighbors=K),
    "mlle": MLLE(n_components=1, n_neighbors=K),
    "nlie": NLIE(n_components=1, n_neighbors=K, n_stress_neighbors=K, seed_landmarks=20,
                 max_iter=20),
}

DUPLICATES = ("fits the iris data, whose rows 101 and 142 coincide: the embedders refuse "
              "duplicate points on purpose (a k-NN graph and LLE weights are undefined there)")
TOO_FEW = ("fits {n} points, fewer than the n_neighbors + 1 = 16 the neighbour graph needs: "
           "a manifold method refuses a set too small for its graph on purpose")
#: check -> (reason, what the failure must say): a declared failure that fails for another
#: reason, or passes, fails this test
EXPECTED = {
    "check_positive_only_tag_during_fit": (DUPLICATES, r"duplicate pair"),
}
GRAPH_EXPECTED = {
    "check_estimators_nan_inf": (TOO_FEW.format(n=10), r"at least 16"),
    "check_n_features_in_after_fitting": (TOO_FEW.format(n=15), r"at least 16"),
}


def expected_failures(name: str) -> dict:
    return {**EXPECTED, **(GRAPH_EXPECTED if name != "pca" else {})}


@pytest.mark.parametrize("name", list(INSTANCES))
def test_check_estimator(name):
    est = INSTANCES[name]
    expected = expected_failures(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        results = check_estimator(
            est, expected_failed_checks={check: why for check, (why, _) in expected.items()})
    status = {}
    for res in results:
        status.setdefault(res["check_name"], set()).add(res["status"])
        if res["status"] == "xfail":
            exc = res["exception"]
            text = f"{exc} {exc.__cause__ or ''}"
            assert re.search(expected[res["check_name"]][1], text), (res["check_name"], text)
    assert len(status) >= 40
    for check in expected:
        assert status[check] == {"xfail"}, f"{check} was declared to fail but: {status[check]}"
    others = {s for c, st in status.items() if c not in expected for s in st}
    assert others <= {"passed", "skipped"}


def _affine_residual(Y, P, Yt, Pt):
    """RMS residual of the best affine map P -> Y, on the fit and on new points, over std(Y)."""
    A = np.c_[P, np.ones(len(P))]
    coef, *_ = np.linalg.lstsq(A, Y, rcond=None)
    s = Y.std(axis=0).max()
    return (np.sqrt(np.mean((A @ coef - Y) ** 2)) / s,
            np.sqrt(np.mean((np.c_[Pt, np.ones(len(Pt))] @ coef - Yt) ** 2)) / s)


@pytest.fixture(scope="module")
def roll_and_new():
    X, P = make_swiss_roll(800)
    Xt, Pt = make_swiss_roll(200, seed=7)
    return X, P, Xt, Pt


@pytest.mark.parametrize("est", [Isomap(n_neighbors=10), Isomap(n_neighbors=None, radius=4.0),
                                 Isomap(n_neighbors=10, aic=True)], ids=["knn", "radius", "aic"])
def test_isomap_transform_reproduces_the_fit_and_places_new_points(roll_and_new, est):
    X, P, Xt, Pt = roll_and_new
    Y = est.fit(X).embedding_
    np.testing.assert_allclose(est.transform(X), Y, rtol=0, atol=1e-10 * np.abs(Y).max())
    r_fit, r_new = _affine_residual(Y, P, est.transform(Xt), Pt)
    # new points are as close to the unrolled coordinates as the training points (0.025, 0.018)
    assert r_fit < 0.03 and r_new < 1.05 * r_fit + 1e-3


def test_isomap_transform_agrees_with_a_fit_on_all_points(roll_and_new):
    X, P, Xt, Pt = roll_and_new
    Z = Isomap(n_neighbors=10).fit(X).transform(Xt)
    U = Isomap(n_neighbors=10).fit(np.r_[X, Xt]).embedding_
    B = np.c_[U[:800], np.ones(800)]
    coef, *_ = np.linalg.lstsq(B, Isomap(n_neighbors=10).fit_transform(X), rcond=None)
    err = np.sqrt(np.mean((np.c_[U[800:], np.ones(200)] @ coef - Z) ** 2)) / Z.std(0).max()
    assert err < 0.03                  # measured 0.021


def test_isomap_radius_transform_refuses_far_points(roll_and_new):
    X, *_ = roll_and_new
    est = Isomap(n_neighbors=None, radius=4.0).fit(X)
    with pytest.raises(InputError, match=r"1 new point\(s\) \(first: rows \[1\]\) lie farther "
                                         r"than radius=4 .* larger radius"):
        est.transform(np.r_[X[:1] + 0.1, [[100.0, 0, 0]]])


@pytest.mark.parametrize("cls,max_err,rms_err", [(LLE, 0.01, 1e-3), (MLLE, 0.01, 1e-3)])
def test_lle_transform_reproduces_the_fit_up_to_the_lle_residual(roll_and_new, cls, max_err,
                                                                  rms_err):
    X, P, Xt, Pt = roll_and_new
    est = cls(n_neighbors=12).fit(X)
    Y, Z = est.embedding_, est.transform(X)
    dev = np.abs(Z - Y) / Y.std(axis=0).max()
    assert dev.max() < max_err and np.sqrt(np.mean(dev ** 2)) < rms_err   # 0.004-0.006, 4-6e-4
    r_fit, r_new = _affine_residual(Y, P, est.transform(Xt), Pt)
    assert abs(r_new - r_fit) < 0.05                    # new points follow the same map
    if cls is MLLE:                                     # MLLE: an affine image of (s, h)
        assert r_fit < 0.03 and r_new < 0.03


def test_lle_transform_of_a_training_point_uses_its_lle_weights():
    X, _ = make_swiss_roll(300)
    est = LLE(n_neighbors=8).fit(X)
    from scipy.spatial import cKDTree

    from pointatlas_embedders.out_of_sample import barycentric_weights

    _, nb = cKDTree(X).query(X[5], k=9)
    w = barycentric_weights(X[nb[1:]][None] - X[5], 1e-3)[0]
    np.testing.assert_allclose(est.transform(X[5:6])[0], w @ est.embedding_[nb[1:]], rtol=1e-12)


def test_nlie_transform_reproduces_the_fit_and_places_new_points(roll_and_new):
    X, P, Xt, Pt = roll_and_new
    est = NLIE(n_stress_neighbors=40, tol=1e-4).fit(X)
    Y = est.embedding_
    np.testing.assert_array_equal(est.transform(X), Y)
    Z = est.transform(Xt)
    r_fit, r_new = _affine_residual(Y, P, Z, Pt)
    assert r_fit < 0.006 and r_new < 0.006             # measured 0.0044 both
    # continuous at the training points: x_i + delta lands |delta| (geodesically) from y_i
    delta = np.array([[0.0, 1e-4, 0.0]])               # along the roll's straight direction
    z = est.transform(X[3:4] + delta)
    assert abs(np.linalg.norm(z - Y[3]) - 1e-4) < 2e-6


def test_nlie_placement_minimises_the_pair_stress():
    from pointatlas_embedders.out_of_sample import _local_stress, stress_placement

    rng = np.random.default_rng(3)
    Yn = rng.random((30, 2)) * 3
    x = np.array([1.4, 1.6])
    g = np.linalg.norm(Yn - x, axis=1) * (1 + 0.05 * rng.normal(size=30))   # noisy distances
    idx = np.arange(30)[None]
    y = stress_placement(Yn, idx, g[None], 0.99, np.array([[0.5, 0.5]]), tol=1e-10)
    E = _local_stress(y, Yn[None], g[None], 0.99, order=0)[0]
    around = y + 1e-4 * np.c_[np.cos(np.arange(8)), np.sin(np.arange(8))]
    assert (_local_stress(around, np.repeat(Yn[None], 8, 0), np.repeat(g[None], 8, 0), 0.99,
                          order=0) > E).all()
    assert np.linalg.norm(y[0] - x) < 0.05


def test_pca_transform_is_the_projection():
    rng = np.random.default_rng(0)
    X = rng.normal(size=(200, 4)) * [5, 2, 0.5, 0.1]
    est = PCA(n_components=2).fit(X)
    np.testing.assert_allclose(est.transform(X), est.embedding_, atol=1e-12)
    Xn = rng.normal(size=(5, 4))
    np.testing.assert_allclose(est.transform(Xn), (Xn - X.mean(0)) @ est.components_.T,
                               atol=1e-12)
    aic = PCA(n_components=2, aic=True).fit(X)
    np.testing.assert_allclose(aic.transform(X), aic.embedding_, atol=1e-10)


def test_scikit_learn_conventions():
    pd = pytest.importorskip("pandas")
    X, _ = make_swiss_roll(200)
    est = Isomap(n_neighbors=10)
    with pytest.raises(NotFittedError):
        est.transform(X)
    est.fit(pd.DataFrame(X, columns=["x", "y", "z"]))
    assert est.n_features_in_ == 3 and list(est.feature_names_in_) == ["x", "y", "z"]
    assert list(est.get_feature_names_out()) == ["isomap0", "isomap1"]
    out = est.set_output(transform="pandas").transform(pd.DataFrame(X[:3], columns=["x", "y", "z"]))
    assert isinstance(out, pd.DataFrame) and list(out.columns) == ["isomap0", "isomap1"]
    est = Isomap(n_neighbors=10).fit(X)
    with pytest.raises(InputError, match="X has 2 features, but Isomap is expecting 3 features"):
        est.transform(X[:, :2])
    with pytest.raises(InputError, match=r"0 feature\(s\) \(shape=\(12, 0\)\) while a minimum "
                                         r"of 1 is required by Isomap"):
        Isomap().fit(np.empty((12, 0)))
    with pytest.raises(ConfigError, match=r"n_components=1 .* 1 feature\(s\)"):
        PCA(n_components=1).fit(X[:, :1])
    with pytest.raises(ValueError, match="Invalid parameter 'k' for estimator"):
        est.set_params(k=3)
    assert clone(est).get_params() == est.get_params()
    pipe = make_pipeline(StandardScaler(), LLE(n_neighbors=10, n_components=2)).fit(X)
    assert pipe.transform(X[:7]).shape == (7, 2)
