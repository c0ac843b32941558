"""Gaussian Shepard partition of unity: sums, derivatives, analytic values, errors."""
import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas_approximants.shepard import Shepard


@pytest.mark.parametrize("d", [1, 2, 3, 6])
@pytest.mark.parametrize("gamma", [0.5, 4.0])
def test_partition_of_unity_and_derivatives(ax, d, gamma):
    nodes = ax.nonuniform_nodes(d, 60, seed=d) if d < 6 else np.random.default_rng(0).random(
        (200, d))
    model = Shepard(gamma=gamma, tol=1e-15).fit(nodes)
    h = float(np.median(model.spacing_))
    x = ax.inside_points(d, 4, seed=d)
    B = model.evaluate(x, order=2)
    P, G, H = ax.dense(B, len(nodes))
    assert P.min() >= 0
    np.testing.assert_allclose(P.sum(1), 1.0, atol=1e-13)
    assert np.abs(G.sum(1)).max() * h < 1e-10
    assert np.abs(H.sum(1)).max() * h * h < 1e-10
    dP, dG = ax.finite_differences(model, x, step=1e-3 * h)
    assert ax.rel_err(G, dP) < 1e-6
    assert ax.rel_err(H, dG) < 1e-6


def test_two_nodes_analytic():
    nodes = np.array([[0.0], [1.0]])
    model = Shepard(gamma=2.0, n_spacing_neighbors=1).fit(nodes)
    np.testing.assert_allclose(model.beta_, 2.0)
    x = np.array([[0.3]])
    B = model.evaluate(x, order=1)
    w0, w1 = np.exp(-2.0 * 0.09), np.exp(-2.0 * 0.49)
    np.testing.assert_allclose(B.values, [w0 / (w0 + w1), w1 / (w0 + w1)], rtol=1e-14)
    # dψ0/dx = ψ0 (g0 - ψ0 g0 - ψ1 g1) = ψ0 ψ1 (-2β x + 2β (x - 1)) = -2β ψ0 ψ1
    psi0, psi1 = B.values
    np.testing.assert_allclose(B.gradients[:, 0], [-4 * psi0 * psi1, 4 * psi0 * psi1],
                               rtol=1e-12)


@settings(max_examples=10, deadline=None)
@given(d=st.sampled_from([1, 2, 3]), gamma=st.floats(0.3, 8.0), seed=st.integers(0, 10**6))
def test_partition_of_unity_property(ax, d, gamma, seed):
    # with large γ a point may sit in a gap no support reaches (flagged): check the others
    nodes = ax.nonuniform_nodes(d, 40, seed=seed)
    model = Shepard(gamma=gamma, outside="flag").fit(nodes)
    B = model.evaluate(ax.inside_points(d, 5, seed=seed), order=1)
    P, G, _ = ax.dense(B, len(nodes))
    ok = np.ones(5, bool) if B.outside is None else ~B.outside
    assert ok.any()
    np.testing.assert_allclose(P[ok].sum(1), 1.0, atol=1e-13)
    assert np.abs(G[ok].sum(1)).max() * np.median(model.spacing_) < 1e-10


def test_surface_in_3d_ambient_space():
    rng = np.random.default_rng(2)
    v = rng.normal(size=(300, 3))
    nodes = v / np.linalg.norm(v, axis=1, keepdims=True)  # sampled unit sphere
    model = Shepard().fit(nodes)
    x = nodes[:5] * 1.001
    B = model.evaluate(x, order=1)
    np.testing.assert_allclose(B.to_csr(300).sum(1), 1.0, atol=1e-13)


def test_point_reached_by_no_support():
    nodes = np.random.default_rng(1).random((50, 2))
    with pytest.raises(InputError, match=r"point 1 at \[9\. +9\.\].*no node's support"):
        Shepard().fit(nodes).evaluate(np.array([[0.5, 0.5], [9.0, 9.0]]))
    B = Shepard(outside="flag").fit(nodes).evaluate(np.array([[0.5, 0.5], [9.0, 9.0]]), 1)
    np.testing.assert_array_equal(B.outside, [False, True])
    assert B.indptr[2] == B.indptr[1] > 0


def test_errors_and_registry():
    with pytest.raises(InputError, match="NaN"):
        Shepard().fit(np.array([[0.0, 0.0], [np.inf, 1.0], [1.0, 1.0]]))
    with pytest.raises(ConfigError, match="gamma"):
        Shepard(gamma=0).fit(np.random.default_rng(0).random((10, 2)))
    assert pointatlas.load_plugin("approximants", "shepard") is Shepard
    assert {f.name for f in dataclasses.fields(Shepard.Config)} == {
        "gamma", "tol", "n_spacing_neighbors", "outside"}
