"""PCA embedder: projection onto the d leading principal directions (thesis §2.1)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.errors import ConfigError

from .base import EmbedderBase
from .checks import AIC, COMPONENTS, check_points


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

        X = check_points(X, min_points=2)
        d = int(self.n_components)
        if d >= X.shape[1]:
            raise ConfigError(
                f"n_components={d} but the points live in R^{X.shape[1]}: PCA needs "
                f"n_components < {X.shape[1]} to reduce the dimension. Lower n_components."
            )
        model = _PCA(n_components=d, svd_solver="full").fit(X)
        self.components_ = model.components_
        self.explained_variance_ratio_ = model.explained_variance_ratio_
        self.mean_ = model.mean_
        return model.transform(X)
