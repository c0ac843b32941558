"""Neighbour graphs on point sets (k nearest neighbours or fixed radius) and their connectivity.

Isomap, NLIE, AIC and the stress measure all approximate geodesic distances by shortest paths
in this graph (thesis §2.2, "Isomap"; Appendix C).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from pointatlas.errors import InputError


def neighbor_graph(X: np.ndarray, n_neighbors: int | None = 12,
                   radius: float | None = None) -> sp.csr_matrix:
    """Symmetric sparse graph whose edge weights are Euclidean distances.

    An edge joins a and b when b is among the ``n_neighbors`` nearest of a *or* a among those of
    b (the union, as Isomap does), or, with ``radius``, when |x_a - x_b| <= radius.
    Units: those of ``X``. Returns an (N, N) CSR matrix with sorted indices and no diagonal.
    """
    from sklearn.neighbors import kneighbors_graph, radius_neighbors_graph

    if n_neighbors is not None:
        G = kneighbors_graph(X, n_neighbors, mode="distance", include_self=False)
    else:
        G = radius_neighbors_graph(X, radius, mode="distance", include_self=False)
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
