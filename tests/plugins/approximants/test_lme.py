"""Local max-ent basis functions: consistency, derivatives, analytic cases, errors."""
import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas_approximants.lme import LocalMaxEnt

N_NODES = {1: 25, 2: 120, 3: 250, 5: 400}


def _identities(ax, model, x, B):
    """Max deviations of the zeroth/first-order consistency conditions (scaled by h)."""
    nodes = model.nodes_
    d = x.shape[1]
    h = model.h_ref_
    P, G, H = ax.dense(B, len(nodes))
    I = np.eye(d)
    g, hh = np.abs(G).max(), np.abs(H).max()  # derivative sums relative to their terms
    return {
        "min p": P.min(),
        "sum p": np.abs(P.sum(1) - 1).max(),
        "sum p x_a": np.abs(P @ nodes - x).max() / h,
        "sum grad": np.abs(G.sum(1)).max() / g,
        "sum grad x_a": np.abs(np.einsum("mak,aj->mjk", G, nodes) - I).max(),
        "sum hess": np.abs(H.sum(1)).max() / hh,
        "sum hess x_a": np.abs(np.einsum("makl,aj->mjkl", H, nodes)).max() / (hh * h),
    }


@pytest.mark.parametrize("d", [1, 2, 3, 5])
@pytest.mark.parametrize("gamma", [0.3, 0.8, 1.8, 4.0])
def test_consistency_conditions(ax, d, gamma):
    nodes = ax.nonuniform_nodes(d, N_NODES[d], seed=d)
    model = LocalMaxEnt(gamma=gamma).fit(nodes)
    x = ax.inside_points(d, 6, seed=d)
    B = model.evaluate(x, order=2)
    dev = _identities(ax, model, x, B)
    assert dev.pop("min p") >= 0.0
    # 1e-10: positions in units of the node spacing, derivative sums relative to the terms
    for name, value in dev.items():
        assert value < 1e-10, (name, value)
    assert B.outside is None


@pytest.mark.parametrize("d", [1, 2, 3, 5])
@pytest.mark.parametrize("gamma", [0.3, 1.0, 4.0])
def test_derivatives_match_finite_differences(ax, d, gamma):
    nodes = ax.nonuniform_nodes(d, N_NODES[d], seed=10 + d)
    # tiny cut-off so that no node enters the support inside the difference stencil
    model = LocalMaxEnt(gamma=gamma, tol=1e-15).fit(nodes)
    x = ax.inside_points(d, 3, seed=d)
    _, G, H = ax.dense(model.evaluate(x, order=2), len(nodes))
    dP, dG = ax.finite_differences(model, x, step=1e-3 * model.h_ref_)
    assert ax.rel_err(G, dP) < 1e-6
    assert ax.rel_err(H, dG) < 1e-6
    assert np.abs(H - H.transpose(0, 1, 3, 2)).max() < 1e-12 * np.abs(H).max()


def test_two_nodes_in_1d_give_linear_interpolation():
    # two nodes: the constraints fix p completely, p_0 = (x1 - x)/(x1 - x0)
    nodes = np.array([[0.5], [2.5]])
    model = LocalMaxEnt(gamma=1.3, n_spacing_neighbors=1).fit(nodes)
    x = np.array([[0.6], [1.0], [2.4]])
    B = model.evaluate(x, order=2)
    np.testing.assert_allclose(B.values.reshape(3, 2)[:, 0], (2.5 - x[:, 0]) / 2.0, atol=1e-12)
    np.testing.assert_allclose(B.gradients.reshape(3, 2), [[-0.5, 0.5]] * 3, atol=1e-10)
    np.testing.assert_allclose(B.hessians, 0.0, atol=1e-9)


def test_uniform_grid_gradient_is_constant_beta_formula(ax):
    # on a Cartesian grid β_a is uniform, and ∇p_a = -p_a J⁻¹ (x - x_a) (Arroyo & Ortiz 2006)
    g = np.linspace(0.0, 1.0, 11)
    nodes = np.array(np.meshgrid(g, g)).reshape(2, -1).T
    model = LocalMaxEnt(gamma=4.0).fit(nodes)
    interior = np.all((nodes > 0.05) & (nodes < 0.95), axis=1)
    np.testing.assert_allclose(model.spacing_[interior], 0.1, rtol=1e-12, atol=0)
    np.testing.assert_allclose(model.beta_[interior], 400.0, rtol=1e-12)
    x = np.array([[0.43, 0.57]])  # its support (radius 0.24) holds interior nodes only
    P, G, _ = ax.dense(model.evaluate(x, order=1), len(nodes))
    y = x[0] - nodes
    J = (P[0, :, None] * y).T @ y
    expected = -P[0, :, None] * np.linalg.solve(J, y.T).T
    np.testing.assert_allclose(G[0], expected, atol=1e-10 * np.abs(expected).max())


@settings(max_examples=12, deadline=None)
@given(d=st.sampled_from([1, 2, 3]), gamma=st.floats(0.3, 4.0), seed=st.integers(0, 10**6))
def test_partition_of_unity_and_linear_reproduction(ax, d, gamma, seed):
    nodes = ax.nonuniform_nodes(d, {1: 15, 2: 60, 3: 120}[d], seed=seed)
    model = LocalMaxEnt(gamma=gamma).fit(nodes)
    x = ax.inside_points(d, 4, seed=seed)
    B = model.evaluate(x, order=1)
    P, G, _ = ax.dense(B, len(nodes))
    assert P.min() >= 0
    np.testing.assert_allclose(P.sum(1), 1.0, atol=1e-12)
    np.testing.assert_allclose(P @ nodes, x, atol=1e-10 * model.h_ref_)
    np.testing.assert_allclose(np.einsum("mak,aj->mjk", G, nodes),
                               np.broadcast_to(np.eye(d), (4, d, d)), atol=1e-9)


def test_point_outside_hull_raises_with_index_and_coordinates(ax):
    nodes = ax.nonuniform_nodes(2, 80, seed=3)
    model = LocalMaxEnt(gamma=0.8).fit(nodes)
    x = np.array([[0.5, 0.5], [1.02, 0.5]])  # just outside, within the nodes' supports
    with pytest.raises(InputError, match=r"point 1 at \[1\.02.*outside the convex hull"):
        model.evaluate(x)
    with pytest.raises(InputError, match="outside the convex hull"):
        model.evaluate(np.array([[50.0, 50.0]]))  # reached by no support


def test_point_outside_hull_is_flagged(ax):
    nodes = ax.nonuniform_nodes(2, 80, seed=3)
    model = LocalMaxEnt(gamma=0.8, outside="flag").fit(nodes)
    x = np.array([[0.5, 0.5], [1.02, 0.5], [-3.0, 9.0], [0.4, 0.6]])
    B = model.evaluate(x, order=2)
    np.testing.assert_array_equal(B.outside, [False, True, True, False])
    counts = np.diff(B.indptr)
    assert counts[1] == counts[2] == 0 and counts[0] > 0 and counts[3] > 0
    assert np.isfinite(B.values).all() and np.isfinite(B.hessians).all()
    P, _, _ = ax.dense(B, len(nodes))
    np.testing.assert_allclose(P[[0, 3]] @ nodes, x[[0, 3]], atol=1e-12)
    assert len(B.values) == len(B.indices) == B.indptr[-1] == len(B.gradients)


@pytest.mark.parametrize(
    "nodes, message",
    [
        (np.array([[0.0, 0.0], [1.0, np.nan], [0.0, 1.0], [1.0, 1.0]]), "NaN"),
        (np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]), "duplicate"),
        (np.array([[0.0, 0.0], [1.0, 0.0]]), r"n > d"),
    ],
)
def test_bad_nodes_raise(nodes, message):
    with pytest.raises(InputError, match=message):
        LocalMaxEnt(n_spacing_neighbors=1).fit(nodes)


@pytest.mark.parametrize(
    "kwargs, name",
    [({"gamma": -1.0}, "gamma"), ({"tol": 2.0}, "tol"), ({"outside": "ignore"}, "outside"),
     ({"max_iter": 0}, "max_iter"), ({"n_spacing_neighbors": 0}, "n_spacing_neighbors")],
)
def test_bad_config_raises_naming_the_field(kwargs, name):
    nodes = np.random.default_rng(0).random((30, 2))
    with pytest.raises(ConfigError, match=name):
        LocalMaxEnt(**kwargs).fit(nodes)


def test_bad_points_and_order_raise(ax):
    model = LocalMaxEnt().fit(ax.nonuniform_nodes(2, 40, seed=0))
    with pytest.raises(InputError, match="dimension"):
        model.evaluate(np.zeros((2, 3)) + 0.5)
    with pytest.raises(InputError, match="NaN"):
        model.evaluate(np.array([[0.5, np.nan]]))
    with pytest.raises(ConfigError, match="order"):
        model.evaluate(np.array([[0.5, 0.5]]), order=3)
    with pytest.raises(InputError, match="fit"):
        LocalMaxEnt().evaluate(np.array([[0.5, 0.5]]))


def test_registry_entry_point_and_config(ax):
    cls = pointatlas.load_plugin("approximants", "lme")
    assert cls is LocalMaxEnt and cls.description
    nodes = ax.nonuniform_nodes(2, 60, seed=1)
    x = ax.inside_points(2, 5, seed=1)
    B = cls(gamma=0.8).fit(nodes).evaluate(x, order=2)
    assert isinstance(B, pointatlas.BasisFunctions)
    assert B.n_points == 5 and B.hessians.shape == (B.indptr[-1], 2, 2)
    fields = {f.name for f in dataclasses.fields(cls.Config)}
    assert fields == {"gamma", "tol", "n_spacing_neighbors", "newton_tol", "max_iter", "outside",
                      "hessians", "reproduction"}
    assert cls.Config().gamma == 0.8 and cls.Config().tol == 1e-10


def test_a_pickled_basis_is_small_and_evaluates_the_same():
    """Sent to a Dask worker, a chart's LME basis leaves its cell lists behind (rebuilt on
    first use) and evaluates bit for bit as the original."""
    import pickle

    import pointatlas

    rng = np.random.default_rng(4)
    nodes = rng.random((400, 2))
    lme = pointatlas.load_plugin("approximants", "lme")(gamma=0.8).fit(nodes)
    x = 0.2 + 0.6 * rng.random((300, 2))
    before = lme.evaluate(x, order=2)
    blob = pickle.dumps(lme)
    assert len(blob) < 12 * nodes.nbytes            # nodes, β, radii, tree: no cell lists
    again = pickle.loads(blob)
    assert "grid_" not in again.__dict__
    after = again.evaluate(x, order=2)
    for name in ("indptr", "indices", "values", "gradients", "hessians"):
        assert np.array_equal(getattr(before, name), getattr(after, name)), name
