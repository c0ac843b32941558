"""PCA embedder: projection onto the d leading principal directions (thesis §2.1).

y = W^T (x - mean), W (D, d) the leading right singular vectors of the centred points; the
same formula maps new points (``transform``), so it reproduces the training embedding exactly.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from .base import EmbedderBase
from .checks import AIC, COMPONENTS, check_components, check_points


@dataclass
class PCAConfig:
    n_components: int = 2            # below the ambient dimension D (checked in fit)
    aic: bool = False                # apply the affine isometric correction
    aic_neighbors: Optional[int] = 12  # neighbours in the AIC stress

    parameter_constraints: ClassVar[dict[str, list]] = {**COMPONENTS, **AIC}


class PCA(EmbedderBase):
    """Principal component analysis (scikit-learn), optionally followed by AIC."""

    Config: ClassVar[type] = PCAConfig
    description: ClassVar[str] = "Principal component analysis: linear projection on d leading directions."

    def __init__(self, *, n_components: int = 2, aic: bool = False,
                 aic_neighbors: Optional[int] = 12):
        self.n_components = n_components
        self.aic = aic
        self.aic_neighbors = aic_neighbors

    def _embed(self, X) -> np.ndarray:
        from sklearn.decomposition import PCA as _PCA

        d = check_components(self.n_components, X, method="PCA")
        X = check_points(X, min_points=2)
        model = _PCA(n_components=d, svd_solver="full").fit(X)
        self.components_ = model.components_
        self.explained_variance_ratio_ = model.explained_variance_ratio_
        self.mean_ = model.mean_
        return self._extend(X)

    def _extend(self, X: np.ndarray) -> np.ndarray:
        """The linear projection y = W^T (x - mean) (``components_`` = W^T, ``mean_``)."""
        return (X - self.mean_) @ self.components_.T
