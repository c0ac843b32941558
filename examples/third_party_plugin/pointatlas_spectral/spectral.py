"""Laplacian eigenmaps (scikit-learn's SpectralEmbedding) as a pointatlas embedder."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np


class SpectralEmbedder:
    """Laplacian eigenmaps of a k-nearest-neighbour graph (wraps sklearn SpectralEmbedding)."""

    description: ClassVar[str] = "Laplacian eigenmaps of a k-NN graph (scikit-learn SpectralEmbedding)."

    @dataclass
    class Config:
        n_components: int = 2
        n_neighbors: int = 10
        random_state: int = 0

    def __init__(self, *, n_components: int = 2, n_neighbors: int = 10, random_state: int = 0):
        self.n_components = n_components
        self.n_neighbors = n_neighbors
        self.random_state = random_state

    def fit(self, X):
        from sklearn.manifold import SpectralEmbedding

        X = np.asarray(X, dtype=float)
        if not np.isfinite(X).all():
            raise ValueError("X contains NaN or inf; remove those points before embedding.")
        if X.shape[0] <= self.n_neighbors:
            raise ValueError(
                f"n_neighbors={self.n_neighbors} needs more than {self.n_neighbors} points; "
                f"got {X.shape[0]}. Lower n_neighbors or give more points."
            )
        model = SpectralEmbedding(n_components=self.n_components, n_neighbors=self.n_neighbors,
                                  affinity="nearest_neighbors", random_state=self.random_state)
        self.embedding_ = model.fit_transform(X)
        return self

    def fit_transform(self, X):
        return self.fit(X).embedding_
