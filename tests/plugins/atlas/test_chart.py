"""Fast paths of the chart module agree with the plain (scipy) versions."""
import numpy as np
import pytest

from pointatlas_approximants.lme import LocalMaxEnt
from pointatlas_atlas import differential_geometry as dg
from pointatlas_atlas.chart import area_element, chart_derivatives, interpolating_control_points
from pointatlas_atlas.partition import knn_edges, knn_graph
from pointatlas_atlas.quadrature import map_rule_to_simplices, simplex_rule


@pytest.fixture(scope="module")
def basis_and_points():
    rng = np.random.default_rng(0)
    nodes = rng.random((120, 2))
    C = rng.random((120, 3))
    x = 0.2 + 0.6 * rng.random((500, 2))
    return LocalMaxEnt(gamma=0.8).fit(nodes), nodes, C, x


@pytest.mark.parametrize("order", [0, 1, 2])
@pytest.mark.parametrize("D", [2, 3])
def test_chart_derivatives_match_sparse_products(basis_and_points, order, D):
    lme, _, C, x = basis_and_points
    B = lme.evaluate(x, order=order)
    ref = dg.chart_derivatives(B, C[:, :D], order)
    got = chart_derivatives(B, C[:, :D], order)
    for r, g in zip(ref, got):
        assert (r is None) == (g is None)
        if r is not None:
            np.testing.assert_allclose(g, r, rtol=1e-13, atol=1e-14)


def test_area_element_matches_determinant(basis_and_points):
    lme, _, C, x = basis_and_points
    _, T, _ = chart_derivatives(lme.evaluate(x, order=1), C, 1)
    np.testing.assert_allclose(area_element(T), dg.area_element(T), rtol=1e-12)


def test_interpolating_control_points_interpolate(basis_and_points):
    lme, nodes, C, _ = basis_and_points
    ctrl = interpolating_control_points(lme, nodes, C)
    X, _, _ = chart_derivatives(lme.evaluate(nodes, order=0), ctrl, 0)
    np.testing.assert_allclose(X, C, atol=1e-10)


def test_knn_edges_are_the_graph_nonzeros():
    P = np.random.default_rng(3).random((60, 3))
    A = knn_graph(P, 6).tocoo()
    row, col = knn_edges(P, 6)
    assert np.array_equal(row, A.row) and np.array_equal(col, A.col)


def test_simplex_weights_are_areas():
    V = np.array([[[0, 0], [2, 0], [0, 1]], [[1, 1], [1, 3], [4, 1]]], float)
    _, w = map_rule_to_simplices(V, simplex_rule(2, 4))
    np.testing.assert_allclose(w.reshape(2, -1).sum(1), [1.0, 3.0])
