"""Quality measures of an embedding Y (N, d) of points X (N, D); each returns a float.

* :func:`stress` - E_S of thesis Appendix E.1 / Table 1: relative mismatch between embedded
  distances and geodesic (graph) distances over each point's k nearest neighbours.
* :func:`trustworthiness` - wraps ``sklearn.manifold.trustworthiness`` (1 is best).
* :func:`residual_variance` - 1 - R^2 between all-pairs geodesic and embedded distances
  (Tenenbaum et al. 2000); O(N^2) memory, for N up to a few thousand.
* :func:`reconstruction_error` - thesis §2.3: each x_a is rebuilt as a weighted average of its
  neighbours, with weights fitted in the embedding (local linear fit of y_a by its embedded
  neighbours); mean of |x_a - sum_b w_ab x_b| / |x_a - xbar| (relative to the centred norm so the
  value does not depend on the origin; thesis Eq. (1) divides by |x_a|).

E_S as printed (thesis L1897, L3567-3570, L3655):
E_S(T) = 1/2 sum_a sum_{b in N(x_a)} ((|T(xi_a - xi_b)| - |x_a - x_b|) / |x_a - x_b|)^2, N(x_a)
the k nearest neighbours of x_a. The extracted text drops the parentheses around the numerator
and shows the exponent 2 before the sums ("2 N ... |xa - xb|"), the layout of the NLIE stress
E_1 = 1/2 sum (|q_ij|/|x_ij| - 1)^2 of Appendix C (L3135, "!2 N"), whose big parentheses
enclose a fraction; ordinary parentheses survive the extraction ("T (xi a"), so the lost ones
are big delimiters around the whole fraction: E_S is dimensionless. Caveat: the gradient and
Hessian printed in Appendix E.1 (L3659, L3665) carry a single 1/|x_ab|, i.e. they belong to 1/2
sum (|zeta_ab| - |x_ab|)^2 / |x_ab| (units of length). Both readings fit the AIC column of
Table 1 equally well (dimensionless with N ~ 700, or the length form with R*sqrt(N) ~ 280) and
give the same AIC gains to 2 % (LLE 73.0x vs 71.8x, MLLE 1113x vs 1113x, N = 1000, R = 1), so
we keep the printed definition. Pairs: the k geodesically nearest points with graph distances
instead of the k Euclidean nearest with |x_a - x_b|: on the Table 1 point set the two pair sets
coincide for 99.99 % of the pairs with identical distances (a k-NN edge is its own shortest
path).
"""
from __future__ import annotations

import numpy as np

from pointatlas.errors import InputError

from .geodesics import all_geodesic_distances, geodesic_neighbors
from .neighbor_graph import connected_neighbor_graph


def min_points(measure: str, n_neighbors: int) -> int:
    """Fewest points for which ``measure`` with ``n_neighbors`` = k is defined.

    'stress', 'residual_variance', 'reconstruction_error': k other points per point, N >= k + 1.
    'trustworthiness': k < N / 2, N >= 2k + 1 (scikit-learn's bound; the normalisation
    2 / (N k (2N - 3k - 1)) of Venna & Kaski needs at least 3k + 1 < 2N).
    """
    k = int(n_neighbors)
    if measure == "trustworthiness":
        return 2 * k + 1
    if measure in ("stress", "residual_variance", "reconstruction_error"):
        return k + 1
    raise ValueError(f"unknown quality measure {measure!r}")


def check_enough_points(measure: str, n_points: int, n_neighbors: int) -> None:
    """Raise :class:`InputError` when ``n_points`` are too few for ``measure`` (see min_points)."""
    need = min_points(measure, n_neighbors)
    if n_points < need:
        rule = "2 n_neighbors + 1" if measure == "trustworthiness" else "n_neighbors + 1"
        raise InputError(
            f"{measure} with n_neighbors={n_neighbors} needs at least {need} points ({rule}), "
            f"got {n_points}. Give more points or lower n_neighbors.")


def stress_on_pairs(Y: np.ndarray, idx: np.ndarray, dist: np.ndarray) -> float:
    """E_S = 1/2 sum_a sum_{b in N(a)} ((|y_a - y_b| - g_ab) / g_ab)^2 for given neighbourhoods.

    ``idx``/``dist``: (N, k) neighbour indices and geodesic distances (see ``geodesic_neighbors``).
    Dimensionless.
    """
    diff = Y[:, None, :] - Y[idx]
    r = np.sqrt(np.einsum("nkd,nkd->nk", diff, diff))
    return float(0.5 * np.sum(((r - dist) / dist) ** 2))


def stress(Y, X, n_neighbors: int = 12, *, graph_neighbors: int | None = None) -> float:
    """Stress E_S of embedding ``Y`` against points ``X`` (thesis Appendix E.1, Table 1).

    N(a) holds the ``n_neighbors`` geodesically nearest points of a; geodesic distances are
    shortest paths in the ``graph_neighbors``-NN graph (default: ``n_neighbors``).
    """
    Y = np.asarray(Y, float)
    X = np.asarray(X, float)
    check_enough_points("stress", X.shape[0], max(n_neighbors, graph_neighbors or 0))
    G = connected_neighbor_graph(X, graph_neighbors or n_neighbors)
    idx, dist = geodesic_neighbors(G, n_neighbors)
    return stress_on_pairs(Y, idx, dist)


def trustworthiness(Y, X, n_neighbors: int = 5) -> float:
    """Trustworthiness in [0, 1] of ``Y`` w.r.t. ``X`` (Venna & Kaski), via scikit-learn."""
    from sklearn.manifold import trustworthiness as _tw

    check_enough_points("trustworthiness", len(X), n_neighbors)
    return float(_tw(np.asarray(X, float), np.asarray(Y, float), n_neighbors=n_neighbors))


def residual_variance(Y, X, n_neighbors: int = 12) -> float:
    """1 - R^2(geodesic distances in X, Euclidean distances in Y) over all pairs."""
    from scipy.spatial.distance import pdist

    X = np.asarray(X, float)
    check_enough_points("residual_variance", X.shape[0], n_neighbors)
    D = all_geodesic_distances(connected_neighbor_graph(X, n_neighbors))
    iu = np.triu_indices(X.shape[0], 1)
    r = np.corrcoef(D[iu], pdist(np.asarray(Y, float)))[0, 1]
    return float(1.0 - r * r)


def reconstruction_error(Y, X, n_neighbors: int = 12, reg: float = 1e-3) -> float:
    """Mean relative error of rebuilding x_a from neighbours with weights fitted in the embedding.

    Weights w_a minimise |y_a - sum_b w_ab y_b|^2 with sum_b w_ab = 1 (regularised by ``reg``
    times the trace of the local Gram matrix, as in LLE); neighbours are the ``n_neighbors``
    nearest of y_a in the embedding.
    """
    from scipy.spatial import cKDTree

    X = np.asarray(X, float)
    Y = np.asarray(Y, float)
    check_enough_points("reconstruction_error", Y.shape[0], n_neighbors)
    _, nb = cKDTree(Y).query(Y, n_neighbors + 1)
    nb = nb[:, 1:]
    Z = Y[nb] - Y[:, None, :]                          # (N, k, d)
    C = np.einsum("nkd,nld->nkl", Z, Z)
    tr = np.trace(C, axis1=1, axis2=2)
    C += (reg * np.where(tr > 0, tr, 1.0))[:, None, None] * np.eye(n_neighbors)
    w = np.linalg.solve(C, np.ones((Y.shape[0], n_neighbors, 1)))[..., 0]
    w /= w.sum(axis=1, keepdims=True)
    Xhat = np.einsum("nk,nkD->nD", w, X[nb])
    scale = np.linalg.norm(X - X.mean(axis=0), axis=1)
    err = np.linalg.norm(X - Xhat, axis=1) / np.where(scale > 0, scale, 1.0)
    return float(err.mean())
