"""Isomap (Tenenbaum et al. 2000; thesis §2.2): classical MDS of graph geodesic distances.

Geodesics: Dijkstra from every point on the k-NN (or radius) graph
(:func:`.geodesics.all_geodesic_distances`: numba, parallel over the sources; the same numbers as
``scipy.sparse.csgraph.dijkstra``, measured timings in :mod:`.geodesics`). The one dense N x N
matrix is overwritten in place by the double centring of classical MDS (scikit-learn's Isomap
keeps the distance matrix and the centred kernel, two N x N arrays).

Out of sample (``transform``): geodesic distances from a new point x through its graph
neighbours x_b, delta(x, x_j) = min_b (|x - x_b| + delta_G(x_b, x_j))
(``neighbor_graph.attach_points``), then the landmark-MDS (Nystrom) formula
y = -1/2 Lambda^{-1/2} V^T (delta_x^2 - mu), mu_j the mean of delta_G(x_j, .)^2 (de Silva &
Tenenbaum 2004; Bengio et al. 2004; :func:`.out_of_sample.mds_extension`), exact on the
training points. Landmark Isomap seeds NLIE on large sets; its landmarks are a
farthest-point sample (:func:`pointatlas_sources.farthest_point.farthest_point_order`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np
from pointatlas_sources.farthest_point import farthest_point_order

from .base import EmbedderBase
from .checks import (AIC, COMPONENTS, GRAPH, check_components, check_graph_fits, check_one_graph,
                     check_points)
from .geodesics import all_geodesic_distances
from .mds import classical_mds, landmark_mds
from .neighbor_graph import attach_points, connected_neighbor_graph
from .out_of_sample import mds_extension

#: new points per block in ``transform``: the block's distance rows take <= 8 * 2^24 bytes
_BLOCK_ENTRIES = 2 ** 24


def isomap_fit(G, n_components: int):
    """Isomap on the connected graph ``G``: (embedding (N, d), top eigenvalues (d,),
    mu (N,) the mean squared geodesic distance of every point, the ``mds_extension`` input)."""
    D = all_geodesic_distances(G)
    mean_sq = np.einsum("ij,ij->i", D, D) / D.shape[0]
    Y, w = classical_mds(D, n_components, overwrite=True)
    return Y, w, mean_sq


def isomap_embedding(X: np.ndarray, n_components: int = 2, n_neighbors: Optional[int] = 12,
                     radius: Optional[float] = None):
    """Isomap of points X (N, D) -> (embedding (N, d), top eigenvalues (d,))."""
    Y, w, _ = isomap_fit(connected_neighbor_graph(X, n_neighbors, radius), n_components)
    return Y, w


def landmark_isomap_embedding(X: np.ndarray, n_components: int = 2, n_neighbors: Optional[int] = 12,
                              radius: Optional[float] = None, n_landmarks: int = 1000,
                              seed: int = 0, graph=None) -> np.ndarray:
    """Landmark Isomap: geodesics from ``n_landmarks`` points (Euclidean farthest-point sample
    started at a point drawn with ``seed``).

    Memory O(n_landmarks N). Falls back to full Isomap when n_landmarks >= N.
    """
    n = X.shape[0]
    if n_landmarks >= n:
        return isomap_embedding(X, n_components, n_neighbors, radius)[0]
    G = graph if graph is not None else connected_neighbor_graph(X, n_neighbors, radius)
    start = int(np.random.default_rng(seed).integers(n))
    land = farthest_point_order(np.ascontiguousarray(X, dtype=np.float64), int(n_landmarks), start)
    D_land = all_geodesic_distances(G, indices=land)
    return landmark_mds(D_land, land, n_components)


@dataclass
class IsomapConfig:
    n_components: int = 2              # below the ambient dimension (checked in fit)
    n_neighbors: Optional[int] = 12    # k-NN graph, or None when radius is given
    radius: Optional[float] = None     # radius graph, or None when n_neighbors is given
    aic: bool = False
    aic_neighbors: Optional[int] = None

    parameter_constraints: ClassVar[dict[str, list]] = {**COMPONENTS, **GRAPH, **AIC}


class Isomap(EmbedderBase):
    """Isomap on a k-NN or radius graph; a disconnected graph is an InputError."""

    Config: ClassVar[type] = IsomapConfig
    description: ClassVar[str] = "Isomap: classical MDS of shortest-path geodesic distances."

    def __init__(self, *, n_components: int = 2, n_neighbors: Optional[int] = 12,
                 radius: Optional[float] = None, aic: bool = False,
                 aic_neighbors: Optional[int] = None):
        self.n_components = n_components
        self.n_neighbors = n_neighbors
        self.radius = radius
        self.aic = aic
        self.aic_neighbors = aic_neighbors

    def estimated_bytes(self, n_points: int, ambient_dim: int) -> int:
        """Bytes of Isomap on N points: the dense N x N geodesic distance matrix (overwritten
        in place by classical MDS), 8 N², plus the graph and the output (EmbedderBase)."""
        return 8 * int(n_points) ** 2 + super().estimated_bytes(n_points, ambient_dim)

    def _check_settings(self) -> None:
        check_one_graph(self.n_neighbors, self.radius)

    def _embed(self, X) -> np.ndarray:
        from scipy.spatial import cKDTree

        d = check_components(self.n_components, X, method="Isomap")
        X = check_points(X, min_points=2)
        check_graph_fits(self.n_neighbors, X.shape[0])
        G = connected_neighbor_graph(X, self.n_neighbors, self.radius)
        Y, w, mean_sq = isomap_fit(G, d)
        self.eigenvalues_ = w
        self.graph_ = G
        self.tree_ = cKDTree(X)
        self.mean_sq_distances_ = mean_sq
        self.projector_ = Y / np.where(w > 0, w, np.inf)     # V Lambda^{-1/2}, 0 if Lambda <= 0
        return Y

    def _extend(self, X: np.ndarray) -> np.ndarray:
        """Nystrom / landmark-MDS extension (module docstring), the new points in blocks."""
        n = self.graph_.shape[0]
        block = max(1, _BLOCK_ENTRIES // (n + 1))
        out = np.empty((X.shape[0], self.projector_.shape[1]))
        for a in range(0, X.shape[0], block):
            Xb = X[a:a + block]
            G = attach_points(self.graph_, self.tree_, Xb, self.n_neighbors, self.radius)
            D = all_geodesic_distances(G, indices=n + np.arange(Xb.shape[0]))[:, :n]
            out[a:a + block] = mds_extension(D, self.mean_sq_distances_, self.projector_)
        return out
