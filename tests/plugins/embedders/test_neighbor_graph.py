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
