import numpy as np

from pointatlas_embedders.geodesics import (all_geodesic_distances, geodesic_neighbors,
                                            pairs_from_neighbors)
from pointatlas_embedders.neighbor_graph import neighbor_graph


def test_geodesic_neighbors_match_full_dijkstra():
    X = np.random.default_rng(0).random((300, 3))
    G = neighbor_graph(X, 6)
    idx, dist = geodesic_neighbors(G, 25)
    D = all_geodesic_distances(G)
    np.testing.assert_allclose(np.sort(D, axis=1)[:, 1:26], dist, rtol=1e-12)
    np.testing.assert_allclose(D[np.arange(300)[:, None], idx], dist, rtol=1e-12)


def test_geodesic_distance_on_a_circle_is_arc_length():
    n = 400
    th = 2 * np.pi * np.arange(n) / n
    X = np.c_[np.cos(th), np.sin(th)]
    idx, dist = geodesic_neighbors(neighbor_graph(X, 2), 10)
    chord = 2 * np.sin(np.pi / n)
    # the 9th and 10th nearest are 5 steps away along the circle
    np.testing.assert_allclose(dist[:, 9], 5 * chord, rtol=1e-12)


def test_pairs_weights_count_both_directions():
    idx = np.array([[1], [0], [0]])
    dist = np.array([[1.0], [1.0], [2.0]])
    i, j, g, w = pairs_from_neighbors(idx, dist)
    got = {(a, b): (c, e) for a, b, c, e in zip(i, j, g, w)}
    assert got == {(0, 1): (1.0, 2.0), (0, 2): (2.0, 1.0)}


def test_all_geodesic_distances_equal_scipy_dijkstra():
    from scipy.sparse.csgraph import dijkstra

    X = np.random.default_rng(1).random((400, 3))
    G = neighbor_graph(X, 7)
    np.testing.assert_array_equal(all_geodesic_distances(G), dijkstra(G, directed=False))
    np.testing.assert_array_equal(all_geodesic_distances(G, indices=[3, 99]),
                                  dijkstra(G, directed=False, indices=[3, 99]))


def test_attached_points_get_out_of_sample_geodesics():
    from scipy.spatial import cKDTree

    from pointatlas_embedders.neighbor_graph import attach_points

    rng = np.random.default_rng(2)
    X, Xn = rng.random((300, 3)), rng.random((6, 3))
    G = neighbor_graph(X, 6)
    D = all_geodesic_distances(G)
    A = attach_points(G, cKDTree(X), np.r_[Xn, X[:1]], n_neighbors=6)
    assert A.shape == (307, 307) and A[:300, 300:].nnz == 0      # no edge into a new point
    # delta(x, x_j) = min_b (|x - x_b| + delta_G(x_b, x_j)) over the 6 nearest training x_b
    dist, nb = cKDTree(X).query(Xn, k=6)
    expected = np.min(dist[:, :, None] + D[nb], axis=1)
    got = all_geodesic_distances(A, indices=300 + np.arange(7))[:, :300]
    np.testing.assert_allclose(got[:6], expected, rtol=1e-13)
    np.testing.assert_array_equal(got[6], D[0])                    # a copy of x_0: its own row
    idx, dist_k = geodesic_neighbors(A, 12, sources=300 + np.arange(6))
    np.testing.assert_allclose(dist_k, np.sort(expected, axis=1)[:, :12], rtol=1e-13)
    assert (idx < 300).all()
