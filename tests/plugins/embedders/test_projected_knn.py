"""Exact k nearest neighbours through a projection, against the definition written out."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from pointatlas_embedders.neighbor_graph import neighbor_graph
from pointatlas_embedders.projected_knn import projected_kneighbors


def brute(X, k):
    """Per row, the k other rows by (distance, index), distances from differences."""
    n = len(X)
    idx, dist = np.empty((n, k), int), np.empty((n, k))
    for i in range(n):
        d = np.sqrt(((X - X[i]) ** 2).sum(axis=1))
        j = np.arange(n)
        keep = j != i
        order = np.lexsort((j[keep], d[keep]))[:k]
        idx[i], dist[i] = j[keep][order], d[keep][order]
    return idx, dist


def near_a_plane(n, D, noise, seed):
    """n points near a random 3-D subspace of R^D, offset far from the origin."""
    rng = np.random.default_rng(seed)
    basis = np.linalg.qr(rng.standard_normal((D, 3)))[0]
    X = rng.uniform(-1, 1, (n, 3)) @ basis.T + noise * rng.standard_normal((n, D))
    return X + 50.0 * rng.standard_normal(D)


@settings(max_examples=25, deadline=None)
@given(n=st.integers(30, 300), D=st.integers(16, 60), k=st.integers(1, 12),
       noise=st.sampled_from([0.0, 1e-4, 3e-3]), seed=st.integers(0, 2**31))
def test_the_neighbours_are_the_exact_ones(n, D, k, noise, seed):
    X = near_a_plane(n, D, noise, seed)
    found = projected_kneighbors(X, k)
    assert found is not None          # the points lie near a 3-D subspace: it prunes
    idx, dist = found
    ref_idx, ref_dist = brute(X, k)
    np.testing.assert_allclose(dist, ref_dist, rtol=1e-12, atol=1e-12)
    # each returned distance is that of the returned index (no mix-up of rows)
    np.testing.assert_allclose(dist, np.linalg.norm(X[idx] - X[:, None], axis=2), rtol=1e-12,
                               atol=1e-12)
    clear = np.ones(n, bool)          # rows without a near-tie at the k-th distance
    full = np.sort(np.linalg.norm(X[:, None] - X[None], axis=2), axis=1)[:, 1:]
    if k < n - 1:
        clear = full[:, k] - full[:, k - 1] > 1e-9 * (1 + full[:, k])
    assert np.array_equal(np.sort(idx[clear], axis=1), np.sort(ref_idx[clear], axis=1))


def test_ties_go_to_the_lower_index_and_duplicates_are_neighbours():
    g = np.stack(np.meshgrid(np.arange(12.0), np.arange(12.0)), -1).reshape(-1, 2)
    X = np.zeros((len(g) + 1, 20))
    X[:-1, :2] = g
    X[-1] = X[5]                      # a duplicate of row 5
    idx, dist = projected_kneighbors(X, 4)
    ref_idx, ref_dist = brute(X, 4)
    np.testing.assert_array_equal(idx, ref_idx)
    np.testing.assert_array_equal(dist, ref_dist)
    assert idx[5, 0] == len(g) and dist[5, 0] == 0.0 and idx[-1, 0] == 5


def test_an_isotropic_cloud_is_left_to_the_brute_search():
    X = np.random.default_rng(0).standard_normal((500, 40))
    assert projected_kneighbors(X, 8) is None
    G = neighbor_graph(X, 8)          # by the brute search, with exact edge lengths
    idx, _ = brute(X, 8)
    assert all(set(idx[i]) <= set(G.indices[G.indptr[i]:G.indptr[i + 1]]) for i in range(500))
    d = np.linalg.norm(X[:, None] - X[None], axis=2)
    np.testing.assert_allclose(G.data, d[G.nonzero()], rtol=1e-12)


def test_the_graph_through_the_projection_is_the_brute_graph():
    X = near_a_plane(400, 50, 1e-3, 3)
    G = neighbor_graph(X, 10)
    idx, dist = brute(X, 10)
    rows = np.repeat(np.arange(len(X)), 10)
    B = np.zeros((len(X), len(X)))
    B[rows, idx.ravel()] = dist.ravel()
    B = np.maximum(B, B.T)
    np.testing.assert_allclose(G.toarray(), B, rtol=1e-12, atol=0)


@pytest.mark.parametrize("seed", [0, 1])
def test_neighbours_hidden_from_the_projection_are_found_in_the_ball(seed):
    """A 55 × 55 grid of spacing 1 in a plane, each point moved by 0.5 (standard deviation)
    along 23 other axes: the projection keeps 99.3 % of the variance but 15 of the noise
    axes are outside it, so the nearest in projection are often not the true nearest; the
    second step (every point of the projected ball) finds them."""
    from scipy.spatial import cKDTree

    from pointatlas_embedders import projected_knn as P

    rng = np.random.default_rng(seed)
    k, D = 6, 25
    grid = np.stack(np.meshgrid(np.arange(55.0), np.arange(55.0)), -1).reshape(-1, 2)
    X = np.zeros((len(grid), D))
    X[:, :2] = grid
    X[:, 2:] = 0.5 * rng.standard_normal((len(grid), D - 2))
    idx, dist = projected_kneighbors(X, k)
    ref_dist, ref_idx = cKDTree(X).query(X, k=k + 1)   # exact; no ties in this noise
    np.testing.assert_array_equal(idx, ref_idx[:, 1:])
    np.testing.assert_allclose(dist, ref_dist[:, 1:], rtol=1e-12)
    V, captured = P._projection(X - X.mean(axis=0))
    Z = (X - X.mean(axis=0)) @ V
    _, first = cKDTree(Z).query(Z, k=P.CANDIDATES * k + 1)
    missed = sum(len(set(ref_idx[i, 1:]) - set(first[i])) for i in range(len(X)))
    assert captured >= P.MIN_CAPTURED and missed > 50    # not found by the first step
