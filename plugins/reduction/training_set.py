"""The training set of a model reduction from simulation snapshots (thesis §5.2 "Training set";
Millán & Arroyo, CMAME 261–262 (2013) 118, §5.1).

* :func:`boundary_nodes` — the nodes on the boundary of a triangle mesh (edges used by one
  triangle): pruning the snapshots to these landmark nodes lowers D (thesis: 4 934 × 2 → 868)
  before the nonlinear embedding, while X(q) is still fitted to the full configurations.
* :func:`landmark_columns` — the columns of the flattened (node, dim) snapshot of given nodes.
* :func:`decimate` — a subset in which any two snapshots are at least ``cutoff`` apart
  (Euclidean, units of the snapshots), kept greedily in the given order. Candidate pairs come
  from a k-d tree on the leading principal components (a projection never lengthens a
  distance, so no pair closer than ``cutoff`` is missed) and are confirmed in full dimension.
"""
from __future__ import annotations

import numpy as np

from pointatlas.errors import InputError


def boundary_nodes(triangles: np.ndarray, exclude=None) -> np.ndarray:
    """Sorted indices of the nodes on the mesh boundary, minus the nodes in ``exclude``."""
    tri = np.asarray(triangles, dtype=np.int64)
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    nodes = np.unique(uniq[count == 1])
    if exclude is not None:
        nodes = np.setdiff1d(nodes, np.asarray(exclude, dtype=np.int64))
    return nodes


def landmark_columns(nodes: np.ndarray, n_dim: int = 2) -> np.ndarray:
    """Columns of the flattened (node, dim) vectors that hold ``nodes``' coordinates."""
    nodes = np.asarray(nodes, dtype=np.int64)
    return (nodes[:, None] * n_dim + np.arange(n_dim)[None, :]).ravel()


def decimate(X: np.ndarray, cutoff: float, n_project: int = 8) -> np.ndarray:
    """Indices (increasing) of a greedy subset of the rows of X (N, D) with all pairwise
    distances ≥ ``cutoff``: row i is kept unless an earlier kept row is closer than cutoff."""
    X = np.asarray(X, dtype=np.float64)
    if not (np.isfinite(cutoff) and cutoff >= 0):
        raise InputError(f"decimation cutoff {cutoff!r} is invalid; give a distance >= 0.")
    N = len(X)
    if cutoff == 0 or N < 2:
        return np.arange(N)
    from scipy.spatial import cKDTree

    mean = X.mean(axis=0)
    k = min(n_project, X.shape[1], N)
    _, _, Vt = np.linalg.svd(X[:: max(1, N // 4000)] - mean, full_matrices=False)
    Y = (X - mean) @ Vt[:k].T
    pairs = cKDTree(Y).query_pairs(cutoff, output_type="ndarray")
    if len(pairs):
        d2 = np.empty(len(pairs))
        for s in range(0, len(pairs), 200_000):
            a, b = pairs[s:s + 200_000].T
            d2[s:s + 200_000] = np.einsum("ij,ij->i", X[a] - X[b], X[a] - X[b])
        pairs = np.sort(pairs[d2 < cutoff * cutoff], axis=1)
    return _greedy(N, pairs)


def _greedy(N: int, pairs: np.ndarray) -> np.ndarray:
    """Keep rows in order, dropping every later row paired with a kept one."""
    from scipy.sparse import csr_matrix

    if not len(pairs):
        return np.arange(N)
    A = csr_matrix((np.ones(len(pairs), bool), (pairs[:, 0], pairs[:, 1])), shape=(N, N))
    dropped = np.zeros(N, bool)
    indptr, indices = A.indptr, A.indices
    for i in range(N):
        if not dropped[i]:
            dropped[indices[indptr[i]:indptr[i + 1]]] = True
    return np.flatnonzero(~dropped)
