"""Shared fit/fit_transform/AIC logic of the embedder plugins (scikit-learn conventions)."""
from __future__ import annotations

import dataclasses
from typing import ClassVar

import numpy as np

from .checks import check_int


class EmbedderBase:
    """Subclasses define ``Config``, ``description``, ``__init__`` (store only) and ``_embed(X)``.

    ``fit`` validates, embeds (``embedding_raw_``) and, when ``aic`` is true, applies the affine
    isometric correction (``embedding_``, ``aic_matrix_``, ``stress_raw_``, ``stress_``).
    """

    Config: ClassVar[type]
    description: ClassVar[str]

    def get_params(self, deep: bool = True) -> dict:
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self.Config)}

    def set_params(self, **params):
        for k, v in params.items():
            setattr(self, k, v)
        return self

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"

    def _aic_neighbors(self) -> int:
        k = getattr(self, "aic_neighbors", None)
        if k is None:
            k = getattr(self, "n_neighbors", None) or 12
        return check_int("aic_neighbors", k, low=1, fix="Typical value: 12.")

    def estimated_bytes(self, n_points: int, ambient_dim: int) -> int:
        """Bytes ``fit`` needs for ``n_points`` points in R^ambient_dim, to refuse a too-large
        request before starting: here the input, the output and a k-NN graph (weights and
        indices, both directions), 8 (D + d + 4k) N. Embedders with dense N x N work override it.
        """
        k = getattr(self, "n_neighbors", None) or 12
        d = getattr(self, "n_components", 2)
        return 8 * int(n_points) * (int(ambient_dim) + int(d) + 4 * int(k))

    def _embed(self, X: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def fit(self, X, y=None):
        Y = self._embed(X)
        X = np.asarray(X, float)
        self.embedding_raw_ = Y
        self.embedding_ = Y
        if self.aic:
            from .aic import affine_isometric_correction

            res = affine_isometric_correction(Y, X, n_neighbors=self._aic_neighbors())
            self.embedding_ = res.embedding
            self.aic_matrix_ = res.matrix
            self.stress_raw_ = res.stress_before
            self.stress_ = res.stress_after
        return self

    def fit_transform(self, X, y=None) -> np.ndarray:
        return self.fit(X).embedding_
