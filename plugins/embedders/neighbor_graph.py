"""Neighbour graphs on point sets (k nearest neighbours or fixed radius) and their connectivity.

Isomap, NLIE, AIC and the stress measure all approximate geodesic distances by shortest paths
in this graph (thesis §2.2, "Isomap"; Appendix C). :func:`attach_points` appends new points to a
training graph, for the out-of-sample extensions (``transform``) of Isomap and NLIE.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from pointatlas.errors import InputError

from .projected_knn import edge_lengths, projected_kneighbors


def neighbor_graph(X: np.ndarray, n_neighbors: int | None = 12,
                   radius: float | None = None) -> sp.csr_matrix:
    """Symmetric sparse graph whose edge weights are Euclidean distances.

    An edge joins a and b when b is among the ``n_neighbors`` nearest of a *or* a among those of
    b (the union, as Isomap does), or, with ``radius``, when |x_a - x_b| <= radius.
    The neighbours are searched on the centred points and every edge length is then
    recomputed as |x_a - x_b| from the coordinates: in high dimension scikit-learn's brute
    search uses |x|² + |y|² - 2 x·y, which on snapshots far from the origin (898 coordinates
    of a body, spacing 1e-2) errs by 3e-7 relative; the lengths here are exact to round-off.
    Above 15 coordinates, k nearest neighbours are searched through a projection
    (:mod:`.projected_knn`, exact, ties to the lower index) where it prunes.
    Units: those of ``X``. Returns an (N, N) CSR matrix with sorted indices and no diagonal.
    """
    from sklearn.neighbors import kneighbors_graph, radius_neighbors_graph

    X = np.asarray(X, dtype=np.float64)
    found = (projected_kneighbors(X, int(n_neighbors))
             if n_neighbors is not None and X.shape[1] > 15 else None)
    if found is not None:  # exact, and found through a projection (high dimension)
        idx, dist = found
        n, k = idx.shape
        G = sp.csr_matrix((dist.ravel(), idx.ravel(), np.arange(0, n * k + 1, k)), shape=(n, n))
    else:
        centred = X - X.mean(axis=0)
        G = (kneighbors_graph(centred, n_neighbors, mode="distance", include_self=False)
             if n_neighbors is not None else
             radius_neighbors_graph(centred, radius, mode="distance", include_self=False)).tocsr()
        rows = np.repeat(np.arange(G.shape[0], dtype=np.int64), np.diff(G.indptr))
        G.data = edge_lengths(X, rows, G.indices.astype(np.int64))
    G = G.maximum(G.T).tocsr()
    G.sort_indices()
    return G


def describe_graph(n_neighbors: int | None, radius: float | None) -> str:
    return (f"{n_neighbors}-nearest-neighbour graph" if n_neighbors is not None
            else f"radius-{radius:g} neighbour graph")


def check_connected(G: sp.spmatrix, *, what: str = "neighbour graph",
                    fix: str = "increase n_neighbors (or radius)") -> None:
    """Raise :class:`InputError` if ``G`` has more than one connected component.

    The message names the number of components, their sizes (largest first) and the fix.
    """
    n_comp, labels = connected_components(G, directed=False)
    if n_comp > 1:
        sizes = np.sort(np.bincount(labels))[::-1]
        shown = sizes[:10].tolist()
        more = "" if n_comp <= 10 else f" (+{n_comp - 10} more)"
        raise InputError(
            f"the {what} is disconnected: {n_comp} connected components of sizes {shown}{more}. "
            f"Geodesic distances are undefined between components: {fix}, or partition the data "
            "and embed each component separately."
        )


def connected_neighbor_graph(X: np.ndarray, n_neighbors: int | None = 12,
                             radius: float | None = None) -> sp.csr_matrix:
    """:func:`neighbor_graph` followed by :func:`check_connected` with a fix naming the parameter."""
    G = neighbor_graph(X, n_neighbors, radius)
    param = f"n_neighbors (now {n_neighbors})" if n_neighbors is not None else f"radius (now {radius:g})"
    check_connected(G, what=describe_graph(n_neighbors, radius), fix=f"increase {param}")
    return G


def attach_points(G: sp.csr_matrix, tree, X_new: np.ndarray, n_neighbors: int | None = 12,
                  radius: float | None = None) -> sp.csr_matrix:
    """The training graph ``G`` (N, N) with M new points appended as nodes N..N+M-1.

    New point x gets one-way edges x -> x_b to its ``n_neighbors`` nearest training points
    (or to those within ``radius``), of length |x - x_b|; no edge enters a new node, so a
    shortest path from x leaves it once and then runs in the training graph:
    delta(x, x_j) = min_b (|x - x_b| + delta_G(x_b, x_j)), the out-of-sample geodesic distance of
    Isomap (Bengio et al. 2004, "Out-of-sample extensions for LLE, Isomap, MDS, Eigenmaps and
    spectral clustering", §4). ``tree`` is a ``scipy.spatial.cKDTree`` of the training points.
    A point that coincides with x_b gets an edge of length 0 (kept as an explicit zero).
    Returns an (N + M, N + M) CSR matrix.
    """
    G = sp.csr_matrix(G)
    n, m = G.shape[0], X_new.shape[0]
    if n_neighbors is not None:
        k = min(int(n_neighbors), n)
        dist, idx = tree.query(X_new, k=k)
        dist, idx = dist.reshape(m, k), idx.reshape(m, k)
        counts = np.full(m, k)
        idx, dist = idx.ravel(), dist.ravel()
    else:
        lists = tree.query_ball_point(X_new, r=radius)
        counts = np.array([len(c) for c in lists])
        if (counts == 0).any():
            far = np.flatnonzero(counts == 0)
            raise InputError(
                f"{far.size} new point(s) (first: rows {far[:5].tolist()}) lie farther than "
                f"radius={radius:g} from every training point, so the radius graph cannot reach "
                "them. Transform points near the training set, or refit with a larger radius.")
        idx = np.concatenate([np.asarray(c, np.int64) for c in lists])
        rows = np.repeat(np.arange(m), counts)
        dist = np.linalg.norm(X_new[rows] - tree.data[idx], axis=1)
    indptr = np.concatenate([G.indptr, G.indptr[-1] + np.cumsum(counts)]).astype(np.int64)
    indices = np.concatenate([G.indices, idx]).astype(np.int64)
    data = np.concatenate([G.data, dist]).astype(np.float64)
    return sp.csr_matrix((data, indices, indptr), shape=(n + m, n + m))
