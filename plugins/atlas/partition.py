"""Partition of the geometric markers Q into patches (thesis §3, L125–200; Paper 2 §3.1).

The markers are split into L groups I_κ by METIS on a symmetrised k-nearest-neighbour graph.
A patch whose chart is not acceptable (disconnected, folded or too distorted when embedded
in R^d) is re-partitioned recursively into two (thesis: "we proceed by recursively
re-partitioning such patches"). The acceptance test is supplied by the caller (the atlas
builds the chart and measures it); :func:`embedding_defects` gives the measures.

Everything done per patch costs the patch's size, not N (at 10⁶ points and 6 700 patches an
O(N) step per patch is minutes): the labels are grouped once (:func:`label_groups`), a
patch's subgraph and its share ψ_κ of the partition of unity are read from its own rows and
columns (:func:`subgraph`, :func:`patch_share`).
"""
from __future__ import annotations

import math
from typing import Callable, Iterator, Optional

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import Delaunay, cKDTree

from pointatlas.errors import ConfigError, InputError


def label_groups(labels) -> Iterator[tuple[int, np.ndarray]]:
    """(k, np.flatnonzero(labels == k)) for every k in np.unique(labels), in that order, from
    one stable sort: O(n log n) where the loop over k with ``labels == k`` is O(n·K) (at 10⁶
    points and 6 700 patches, seconds per loop)."""
    labels = np.asarray(labels)
    order = np.argsort(labels, kind="stable")
    ordered = labels[order]
    starts = np.flatnonzero(np.r_[True, ordered[1:] != ordered[:-1]]) if labels.size else \
        np.zeros(0, np.int64)
    ends = np.r_[starts[1:], labels.size]
    for a, b in zip(starts, ends):
        yield int(ordered[a]), order[a:b]


def label_members(labels, wanted) -> list[np.ndarray]:
    """[np.flatnonzero(labels == k) for k in wanted], grouping the labels once
    (:func:`label_groups`)."""
    groups = dict(label_groups(labels))
    return [groups.get(int(k), np.zeros(0, np.int64)) for k in wanted]


def patch_share(weights, members: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """ψ_κ = Σ_{A ∈ members} w_A at the points: ``weights`` is the (N, M) CSC matrix of the
    partition of unity's w_A at the points. Returns (rows, ψ_κ there) over the points some
    member reaches (sorted). Reads only the members' columns, so a patch costs its own
    size, not N; the sums are those of ``weights[:, members].sum(axis=1)`` bit for bit (the
    same order of addition)."""
    sub = weights[:, members]
    rows, inverse = np.unique(sub.indices, return_inverse=True)
    return rows, np.bincount(inverse, weights=sub.data, minlength=rows.size)


def share_at(rows: np.ndarray, psi: np.ndarray, at: np.ndarray) -> np.ndarray:
    """ψ_κ at the points ``at`` from :func:`patch_share`'s (rows, ψ_κ): 0 where it is not."""
    out = np.zeros(len(at))
    if rows.size:
        pos = np.minimum(np.searchsorted(rows, at), rows.size - 1)
        hit = rows[pos] == at
        out[hit] = psi[pos[hit]]
    return out


def knn_graph(points: np.ndarray, n_neighbors: int) -> csr_matrix:
    """Symmetrised k-NN adjacency (unweighted, no self loops) of the (n, D) points."""
    n = points.shape[0]
    k = min(int(n_neighbors), n - 1)
    if k < 1:
        raise InputError(f"a neighbour graph needs at least 2 points; got {n}.")
    _, nb = cKDTree(points).query(points, k=k + 1)
    rows = np.repeat(np.arange(n), k)
    cols = nb[:, 1:].ravel()
    A = coo_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n)).tocsr()
    A = ((A + A.T) > 0).astype(np.float64)
    A.setdiag(0)
    A.eliminate_zeros()
    return A.tocsr()


def knn_edges(points: np.ndarray, n_neighbors: int) -> tuple[np.ndarray, np.ndarray]:
    """(row, col) of the symmetrised k-NN graph's edges, both directions, sorted row-major:
    the non-zeros of :func:`knn_graph` in CSR/COO order, without building the matrix."""
    n = points.shape[0]
    k = min(int(n_neighbors), n - 1)
    if k < 1:
        raise InputError(f"a neighbour graph needs at least 2 points; got {n}.")
    _, nb = cKDTree(points).query(points, k=k + 1)
    rows = np.repeat(np.arange(n, dtype=np.int64), k)
    cols = nb[:, 1:].ravel().astype(np.int64)
    code = np.unique(np.concatenate([rows * n + cols, cols * n + rows]))
    row, col = np.divmod(code, n)
    off = row != col
    return row[off], col[off]


def metis_parts(adjacency: csr_matrix, n_parts: int) -> np.ndarray:
    """Labels (n,) of a METIS k-way partition of the graph into n_parts parts."""
    import pymetis

    n = adjacency.shape[0]
    if n_parts <= 1 or n <= n_parts:
        return np.zeros(n, dtype=np.int64) if n_parts <= 1 else np.arange(n) % n_parts
    A = adjacency.tocsr()
    A.sort_indices()
    _, parts = pymetis.part_graph(
        int(n_parts), adjacency=pymetis.CSRAdjacency(A.indptr.astype(np.int64),
                                                     A.indices.astype(np.int64)))
    return np.asarray(parts, dtype=np.int64)


def subgraph(adjacency: csr_matrix, idx: np.ndarray) -> csr_matrix:
    """``adjacency[idx][:, idx]`` (distinct idx) with sorted indices, in O(the rows' entries):
    scipy's column indexing allocates an array of all N columns, O(N) a patch."""
    rows = adjacency.tocsr()[idx]
    order = np.argsort(idx, kind="stable")
    pos = np.minimum(np.searchsorted(idx[order], rows.indices), max(len(idx) - 1, 0))
    keep = idx[order][pos] == rows.indices if len(idx) else np.zeros(0, bool)
    row_of = np.repeat(np.arange(len(idx)), np.diff(rows.indptr))[keep]
    sub = coo_matrix((rows.data[keep], (row_of, order[pos[keep]])),
                     shape=(len(idx), len(idx))).tocsr()
    sub.sort_indices()
    return sub


def split_disconnected(adjacency: csr_matrix, labels: np.ndarray) -> np.ndarray:
    """Relabel so that every part induces a connected subgraph (components become parts)."""
    out = np.empty_like(labels)
    next_label = 0
    for _, idx in label_groups(labels):
        n_comp, comp = connected_components(subgraph(adjacency, idx), directed=False)
        out[idx] = next_label + comp
        next_label += n_comp
    return out


def is_connected(adjacency: csr_matrix, indices: np.ndarray) -> bool:
    n_comp, _ = connected_components(subgraph(adjacency, indices), directed=False)
    return n_comp == 1


def partition_markers(markers: np.ndarray, n_parts: int, n_neighbors: int = 10
                      ) -> tuple[np.ndarray, csr_matrix]:
    """METIS partition of the markers into (about) n_parts connected patches.

    Returns the labels (M,) in 0..L-1 and the k-NN adjacency used.
    """
    if isinstance(n_parts, bool) or not isinstance(n_parts, (int, np.integer)) or n_parts < 1:
        raise ConfigError(f"n_patches = {n_parts!r} is invalid; it must be an integer >= 1.")
    A = knn_graph(markers, n_neighbors)
    labels = split_disconnected(A, metis_parts(A, int(n_parts)))
    return labels, A


#: a patch is bisected only if each half can keep at least this many markers
MIN_PATCH_MARKERS = 8


def bisect_patch(adjacency: csr_matrix, members: np.ndarray) -> list[np.ndarray]:
    """The marker sets of the METIS bisection of patch ``members`` (connected parts)."""
    sub = subgraph(adjacency, members)
    halves = split_disconnected(sub, metis_parts(sub, 2))
    return [members[halves == lab] for lab in np.unique(halves)]


def refine_partition(labels: np.ndarray, adjacency: csr_matrix,
                     acceptable: Callable[[np.ndarray], bool], max_depth: int = 6,
                     min_size: int = MIN_PATCH_MARKERS,
                     prefetch: Optional[Callable[[list], None]] = None
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Recursively bisect (METIS) every patch for which ``acceptable(marker_indices)`` fails.

    ``acceptable`` may itself repair the patch (re-embed it, :mod:`.chart_repair`); only a
    patch it still rejects is split. A patch with fewer than 2·min_size markers or at depth
    max_depth is kept as it is. Returns new labels 0..L'-1 and, per final patch, whether it
    passed the test and its split depth (0: a patch of the initial partition).

    The patches are tested depth by depth; ``prefetch(list of marker-index arrays)`` is
    called with each depth's patches first (the atlas embeds them there in one map on its
    executor, :mod:`pointatlas.executor`). The result does not depend on the order.
    """
    queue = [(idx, 0) for _, idx in label_groups(labels)]
    final: list[tuple[np.ndarray, bool, int]] = []
    while queue:
        if prefetch is not None:
            prefetch([idx for idx, _ in queue])
        split = []
        for idx, depth in queue:
            ok = acceptable(idx)
            if ok or depth >= max_depth or idx.size < 2 * min_size:
                final.append((idx, ok, depth))
                continue
            split += [(half, depth + 1) for half in bisect_patch(adjacency, idx)]
        queue = split
    out = np.empty_like(labels)
    final.sort(key=lambda item: item[0].min())
    for k, (idx, _, _) in enumerate(final):
        out[idx] = k
    return (out, np.array([ok for _, ok, _ in final], dtype=bool),
            np.array([depth for _, _, depth in final], dtype=np.int64))


#: adjacent triangles whose image normals n_t·n_s fall below this are a fold. Where ξ folds
#: over a smooth surface, the two triangles across the fold line lie in almost the same plane
#: but face opposite ways (n_t·n_s ≈ −1: measured −0.95 to −1.0 on folded patches of the
#: Stanford bunny). A valid chart across a crease of angle φ (a graph over its bisector plane)
#: has triangles straddling it whose normals are up to φ apart: on the bunny's base rim,
#: n_t·n_s down to −0.27 (~105°) on charts that do not fold, which n_t·n_s < 0 took for folds.
#: −0.5 (120°) lies between; the cloud check calls creases sharper than 140° knife edges.
FOLD_COSINE = -0.5


def embedding_defects(points: np.ndarray, xi: np.ndarray, n_neighbors: int = 8
                      ) -> dict[str, float]:
    """How far an embedding ξ (n, d) of points (n, D) is from a good chart.

    - ``stress``: Σ_edges (|ξ_a − ξ_b| − |P_a − P_b|)² / Σ_edges |P_a − P_b|² over the k-NN
      edges (a normalised version of the stress E_S of thesis Appendix E.1);
    - ``flip_fraction``: fraction of pairs of adjacent Delaunay triangles of ξ whose images
      in R^3 (vertices ordered counter-clockwise in ξ) have opposite normals (more than 120°
      apart, :data:`FOLD_COSINE`): a fold;
    - ``max_distortion`` / ``distortion``: largest / 95th-percentile ratio of singular values of
      the affine map ξ → P over the non-sliver triangles (edges < 3 median k-NN distances).

    The triangle measures are those of a surface in R^3; other (d, D) use the simplices of
    :func:`simplex_defects`.
    """
    row, col = knn_edges(points, n_neighbors)
    dx = np.linalg.norm(points[row] - points[col], axis=1)
    dxi = np.linalg.norm(xi[row] - xi[col], axis=1)
    out = {"stress": float(np.sum((dxi - dx) ** 2) / np.sum(dx**2))}
    d = xi.shape[1]
    if len(xi) < d + 2:
        r = float(np.max(dxi / dx) / np.min(dxi / dx))
        out.update(flip_fraction=0.0, max_distortion=r, distortion=r)
        return out
    if d != 2 or points.shape[1] != 3:
        out.update(simplex_defects(points, xi, float(np.median(dx))))
        return out
    tri = Delaunay(xi)
    S = tri.simplices.copy()
    e1, e2 = xi[S[:, 1]] - xi[S[:, 0]], xi[S[:, 2]] - xi[S[:, 0]]
    neg = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
    S[neg, 1], S[neg, 2] = S[neg, 2], S[neg, 1].copy()
    P0, P1, P2 = points[S[:, 0]], points[S[:, 1]], points[S[:, 2]]
    edge = np.max(np.stack([np.linalg.norm(P1 - P0, axis=1), np.linalg.norm(P2 - P0, axis=1),
                            np.linalg.norm(P2 - P1, axis=1)]), axis=0)
    # slivers (hull-boundary or near-degenerate triangles in ξ) have unreliable normals
    l2 = (np.sum(e1**2, 1) + np.sum(e2**2, 1) + np.sum((e2 - e1) ** 2, 1))
    shape_quality = 4.0 * np.sqrt(3.0) * 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) / l2
    good = (edge < 3.0 * np.median(dx)) & (shape_quality > 0.2)
    normal = np.cross(P1 - P0, P2 - P0)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-300
    # pairs (t, s) of adjacent good triangles, s > t (s = -1: no neighbour)
    t_idx = np.repeat(np.arange(len(S)), tri.neighbors.shape[1])
    s_idx = tri.neighbors.ravel()
    pair = (s_idx > t_idx) & good[t_idx] & good[np.maximum(s_idx, 0)]
    if pair.any():
        ta, sa = t_idx[pair], s_idx[pair]
        out["flip_fraction"] = float(np.mean(np.sum(normal[ta] * normal[sa], 1) < FOLD_COSINE))
    else:
        out["flip_fraction"] = 0.0
    # affine map ξ → P on each good triangle: P_e = F ξ_e with F (3, 2)
    E_xi = np.stack([xi[S[:, 1]] - xi[S[:, 0]], xi[S[:, 2]] - xi[S[:, 0]]], axis=2)  # (t,2,2)
    E_P = np.stack([P1 - P0, P2 - P0], axis=2)  # (t,3,2)
    F = E_P[good] @ np.linalg.inv(E_xi[good])
    sv = np.linalg.svd(F, compute_uv=False)
    ratio = sv[:, 0] / np.maximum(sv[:, -1], 1e-300) if len(sv) else np.ones(1)
    out["max_distortion"] = float(np.max(ratio))
    out["distortion"] = float(np.quantile(ratio, 0.95))
    return out


def regular_simplex_volume(d: int, edge: np.ndarray) -> np.ndarray:
    """d-volume of the regular d-simplex of edge length ``edge``: edge^d/d!·sqrt((d+1)/2^d)."""
    return edge**d / math.factorial(d) * math.sqrt((d + 1) / 2.0**d)


def simplex_defects(points: np.ndarray, xi: np.ndarray, h: float) -> dict[str, float]:
    """Fold and distortion measures of an embedding ξ (n, d) of points (n, D), any d and D.

    Simplices: consecutive nodes in ξ order for d = 1, the Delaunay simplices of ξ for d ≥ 2.
    On each, the affine map ξ → P has the (D, d) gradient F = E_P E_ξ⁻¹ (edge matrices).

    - ``flip_fraction``: fraction of pairs of adjacent good simplices with det(F_sᵀ F_t) < 0:
      the map turns over across their common face, a fold (for a surface in R^3 this is the
      sign of n_s·n_t, Binet–Cauchy). For d = 1 a segment longer than 3 h in R^D (the
      embedding interleaves two distant pieces of the curve) also counts as a fold.
    - ``max_distortion`` / ``distortion``: largest / 95th-percentile singular-value ratio of
      F over the good simplices; for d = 1 (one singular value per segment) the ratio of the
      95th to the 5th percentile of the stretch |ΔP|/|Δξ| instead.

    Good simplices have all edges in R^D below 3 h (h: median k-NN distance) and, for d ≥ 2,
    ξ-volume above 0.2 of the regular simplex of their rms edge (no hull slivers).
    """
    d = xi.shape[1]
    if d == 1:
        o = np.argsort(xi[:, 0])
        dP = np.diff(points[o], axis=0)
        lengths = np.linalg.norm(dP, axis=1)
        stretch = lengths / np.maximum(np.diff(xi[o, 0]), 1e-300)
        turn = np.einsum("ij,ij->i", dP[1:], dP[:-1]) < 0
        jump = lengths > 3.0 * h
        folds = np.concatenate([turn, jump])
        q05, q95 = np.quantile(stretch, [0.05, 0.95])
        return {"flip_fraction": float(np.mean(folds)),
                "max_distortion": float(stretch.max() / max(stretch.min(), 1e-300)),
                "distortion": float(q95 / max(q05, 1e-300))}
    tri = Delaunay(xi)
    S = tri.simplices
    E_xi = xi[S[:, 1:]] - xi[S[:, :1]]                       # (t, d, d) rows: edges
    E_P = points[S[:, 1:]] - points[S[:, :1]]                # (t, d, D)
    vol = np.abs(np.linalg.det(E_xi)) / math.factorial(d)
    pairs = np.array([(i, j) for i in range(d + 1) for j in range(i + 1, d + 1)])
    edge_xi = np.linalg.norm(xi[S[:, pairs[:, 0]]] - xi[S[:, pairs[:, 1]]], axis=2)
    edge_P = np.linalg.norm(points[S[:, pairs[:, 0]]] - points[S[:, pairs[:, 1]]], axis=2)
    rms = np.sqrt(np.mean(edge_xi**2, axis=1))
    good = (edge_P.max(axis=1) < 3.0 * h) & (vol > 0.2 * regular_simplex_volume(d, rms))
    F = np.zeros((len(S), points.shape[1], d))
    F[good] = np.swapaxes(np.linalg.solve(E_xi[good], E_P[good]), 1, 2)  # F E_ξᵀ = E_Pᵀ
    t_idx = np.repeat(np.arange(len(S)), d + 1)
    s_idx = tri.neighbors.ravel()
    pair = (s_idx > t_idx) & good[t_idx] & good[np.maximum(s_idx, 0)]
    flip = 0.0
    if pair.any():
        G = np.einsum("tid,tie->tde", F[t_idx[pair]], F[s_idx[pair]])
        flip = float(np.mean(np.linalg.det(G) < 0))
    sv = np.linalg.svd(F[good], compute_uv=False)
    ratio = sv[:, 0] / np.maximum(sv[:, -1], 1e-300) if len(sv) else np.ones(1)
    return {"flip_fraction": flip, "max_distortion": float(np.max(ratio)),
            "distortion": float(np.quantile(ratio, 0.95))}
