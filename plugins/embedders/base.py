"""Shared fit/fit_transform/AIC logic of the embedder plugins (scikit-learn conventions)."""
from __future__ import annotations

import dataclasses
from typing import ClassVar

import numpy as np

from pointatlas.constraints import validate_parameters


class EmbedderBase:
    """Subclasses define ``Config`` (with its ``parameter_constraints``), ``description``,
    ``__init__`` (store only) and ``_embed(X)``; rules that tie settings together go in
    ``_check_settings``, checks that need the points in ``_embed``.

    ``fit`` validates (:meth:`check_config`), embeds (``embedding_raw_``) and, when ``aic`` is
    true, applies the affine isometric correction (``embedding_``, ``aic_matrix_``,
    ``stress_raw_``, ``stress_``).
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

    def check_config(self) -> None:
        """The checks that need no data, at start-up and in ``fit``: the constraints the
        Config declares (:func:`pointatlas.constraints.validate_parameters`), then the rules
        that tie settings together (:meth:`_check_settings`)."""
        validate_parameters(self)
        self._check_settings()

    def _check_settings(self) -> None:
        """Rules that tie settings together (none here)."""

    def _aic_neighbors(self) -> int:
        k = getattr(self, "aic_neighbors", None)
        if k is None:
            k = getattr(self, "n_neighbors", None) or 12
        return int(k)

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
        self.check_config()
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
