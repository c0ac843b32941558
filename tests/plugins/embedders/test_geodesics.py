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
