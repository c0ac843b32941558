import numpy as np
import pytest

from pointatlas.errors import InputError
from pointatlas_embedders.neighbor_graph import check_connected, connected_neighbor_graph, neighbor_graph


def test_knn_graph_is_symmetric_with_euclidean_weights():
    X = np.random.default_rng(0).random((50, 3))
    G = neighbor_graph(X, 5)
    assert abs(G - G.T).max() == 0
    i, j = G.nonzero()
    np.testing.assert_allclose(G.data, np.linalg.norm(X[i] - X[j], axis=1))
    assert (np.diff(G.indptr) >= 5).all()


def test_radius_graph_edges_within_radius():
    X = np.c_[np.arange(10.0), np.zeros(10)]
    G = neighbor_graph(X, None, radius=1.5)
    assert G.nnz == 2 * 9 and G.data.max() == 1.0


def test_disconnected_graph_names_components_sizes_and_fix():
    rng = np.random.default_rng(1)
    X = np.r_[rng.random((30, 2)), rng.random((12, 2)) + 100.0]
    with pytest.raises(InputError) as e:
        connected_neighbor_graph(X, 5)
    msg = str(e.value)
    assert "2 connected components" in msg and "[30, 12]" in msg
    assert "increase n_neighbors (now 5)" in msg and "partition" in msg


def test_check_connected_passes_on_connected_graph():
    X = np.c_[np.arange(10.0), np.zeros(10)]
    check_connected(neighbor_graph(X, 1))


@pytest.mark.parametrize("radius", [None, 0.05])
def test_edge_lengths_are_exact_on_snapshots_far_from_the_origin(radius):
    """High-dimensional points far from the origin (a body's coordinates, small motions):
    the edge lengths are |x_a - x_b| to round-off, not |x|² + |y|² - 2 x·y (which erred by
    3e-7 relative on the reduced-order snapshots), and the neighbours are the true ones."""
    rng = np.random.default_rng(3)
    t = np.sort(rng.random(400)) * 2 * np.pi
    basis = np.linalg.qr(rng.normal(size=(120, 3)))[0]
    X = 1e3 * (1 + rng.random(120)) + 0.1 * np.column_stack(
        [np.cos(t), np.sin(t), np.sin(2 * t)]) @ basis.T
    G = neighbor_graph(X, None if radius else 6, radius).tocoo()
    exact = np.linalg.norm(X[G.row] - X[G.col], axis=1)
    np.testing.assert_allclose(G.data, exact, rtol=1e-13)
    if radius is None:                           # each point's 6 nearest are its edges
        d = np.linalg.norm(X[:, None] - X[None], axis=2)
        np.fill_diagonal(d, np.inf)
        nearest = np.argsort(d, axis=1)[:, :6]
        G = G.tocsr()
        for a in range(0, 400, 37):
            assert set(nearest[a]) <= set(G.indices[G.indptr[a]:G.indptr[a + 1]])
