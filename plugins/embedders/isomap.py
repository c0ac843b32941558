"""Isomap (Tenenbaum et al. 2000; thesis §2.2): classical MDS of graph geodesic distances.

Own implementation on ``scipy.sparse.csgraph.shortest_path`` with one N x N array overwritten
in place (scikit-learn's Isomap holds several), so it is no slower and lighter than sklearn's.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.errors import ConfigError

from .base import EmbedderBase
from .checks import AIC, COMPONENTS, GRAPH, check_graph_fits, check_one_graph, check_points
from .geodesics import all_geodesic_distances
from .mds import classical_mds, landmark_mds
from .neighbor_graph import connected_neighbor_graph


def isomap_embedding(X: np.ndarray, n_components: int = 2, n_neighbors: Optional[int] = 12,
                     radius: Optional[float] = None):
    """Isomap of points X (N, D) -> (embedding (N, d), top eigenvalues (d,))."""
    G = connected_neighbor_graph(X, n_neighbors, radius)
    D = all_geodesic_distances(G)
    return classical_mds(D, n_components, overwrite=True)


def farthest_point_sample(X: np.ndarray, m: int, seed: int = 0) -> np.ndarray:
    """Indices of ``m`` points spread over X: greedy farthest-point sampling (Euclidean), O(m N)."""
    n = X.shape[0]
    out = np.empty(m, np.int64)
    out[0] = np.random.default_rng(seed).integers(n)
    mind = np.sum((X - X[out[0]]) ** 2, axis=1)
    for a in range(1, m):
        out[a] = int(np.argmax(mind))
        np.minimum(mind, np.sum((X - X[out[a]]) ** 2, axis=1), out=mind)
    return out


def landmark_isomap_embedding(X: np.ndarray, n_components: int = 2, n_neighbors: Optional[int] = 12,
                              radius: Optional[float] = None, n_landmarks: int = 1000,
                              seed: int = 0, graph=None) -> np.ndarray:
    """Landmark Isomap: geodesics from ``n_landmarks`` points (Euclidean farthest-point sample).

    Memory O(n_landmarks N). Falls back to full Isomap when n_landmarks >= N.
    """
    n = X.shape[0]
    if n_landmarks >= n:
        return isomap_embedding(X, n_components, n_neighbors, radius)[0]
    G = graph if graph is not None else connected_neighbor_graph(X, n_neighbors, radius)
    land = farthest_point_sample(X, n_landmarks, seed)
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
        X = check_points(X, min_points=2)
        check_graph_fits(self.n_neighbors, X.shape[0])
        d = int(self.n_components)
        if d >= X.shape[1] or d >= X.shape[0]:
            raise ConfigError(f"n_components={d} must be below the ambient dimension {X.shape[1]} "
                              f"and the number of points {X.shape[0]}; lower n_components.")
        Y, w = isomap_embedding(X, d, self.n_neighbors, self.radius)
        self.eigenvalues_ = w
        return Y
