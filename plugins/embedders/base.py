"""Shared fit/transform/AIC logic of the embedder plugins: scikit-learn estimators.

:class:`EmbedderBase` is a scikit-learn transformer (``BaseEstimator`` + ``TransformerMixin``):
``clone``, ``Pipeline``, ``set_output`` and ``sklearn.utils.estimator_checks.check_estimator``
work on every embedder. The input is checked by scikit-learn's own ``validate_data`` (its
messages, ``n_features_in_``, ``feature_names_in_``); its refusals are raised as
:class:`pointatlas.errors.InputError`, a ``ValueError``, with scikit-learn's message unchanged.
"""
from __future__ import annotations

import dataclasses
from typing import ClassVar

import numpy as np
from sklearn.base import BaseEstimator, ClassNamePrefixFeaturesOutMixin, TransformerMixin
from sklearn.utils.validation import check_is_fitted

from pointatlas.constraints import validate_parameters
from pointatlas.errors import InputError

try:
    from sklearn.utils.validation import validate_data          # scikit-learn >= 1.6
except ImportError:                                              # 1.4, 1.5: the method
    def validate_data(estimator, X, **kwargs):
        return estimator._validate_data(X, **kwargs)


class EmbedderBase(ClassNamePrefixFeaturesOutMixin, TransformerMixin, BaseEstimator):
    """Subclasses define ``Config`` (with its ``parameter_constraints``), ``description``,
    ``__init__`` (store only), ``_embed(X)`` (the training embedding) and ``_extend(X)`` (the
    out-of-sample extension of that embedding to new points); rules that tie settings together
    go in ``_check_settings``, checks that need the points in ``_embed``.

    ``fit`` validates (:meth:`check_config`, then scikit-learn's ``validate_data``), embeds
    (``embedding_raw_``) and, when ``aic`` is true, applies the affine isometric correction
    y -> ybar + (y - ybar) A (``embedding_``, ``aic_matrix_`` A, ``aic_center_`` ybar,
    ``stress_raw_``, ``stress_``). ``transform`` extends the raw embedding to new points and
    applies the same correction, so ``transform`` of the training points reproduces
    ``embedding_`` (exactly for PCA, Isomap and NLIE; up to the LLE reconstruction residual for
    LLE and MLLE, see :mod:`.out_of_sample`).

    ``sklearn.utils.estimator_checks.check_estimator`` passes, but for the checks that feed
    duplicate points or fewer points than the neighbour graph needs, refused on purpose
    (declared with their reasons in ``tests/plugins/embedders/test_sklearn_api.py``).
    """

    Config: ClassVar[type]
    description: ClassVar[str]

    def get_params(self, deep: bool = True) -> dict:
        """The settings: the fields of ``Config`` (the keyword arguments of ``__init__``)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self.Config)}

    def __repr__(self, N_CHAR_MAX: int = 700) -> str:
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

    def _validate_points(self, X, *, reset: bool) -> np.ndarray:
        """scikit-learn's ``validate_data``: a 2-D finite float64 array (at least 2 rows in
        ``fit``) with the ``n_features_in_`` / ``feature_names_in_`` of ``fit``. Its
        ``ValueError`` is re-raised as :class:`InputError` with the same message; a
        ``TypeError`` (sparse, complex or object input) passes unchanged."""
        try:
            return validate_data(self, X, reset=reset, dtype=np.float64,
                                 ensure_min_samples=2 if reset else 1)
        except InputError:
            raise
        except ValueError as exc:
            raise InputError(str(exc)) from None

    def _embed(self, X: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def _extend(self, X: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def fit(self, X, y=None):
        """Embed the points ``X`` (N, D); ``y`` is ignored (scikit-learn convention)."""
        self.check_config()
        X = self._validate_points(X, reset=True)
        Y = self._embed(X)
        self.embedding_raw_ = Y
        self.embedding_ = Y
        self._n_features_out = Y.shape[1]
        for name in ("aic_matrix_", "aic_center_", "stress_raw_"):
            self.__dict__.pop(name, None)       # left over from an earlier fit with aic=True
        if self.aic:
            from .aic import affine_isometric_correction

            res = affine_isometric_correction(Y, X, n_neighbors=self._aic_neighbors())
            self.embedding_ = res.embedding
            self.aic_matrix_ = res.matrix
            self.aic_center_ = Y.mean(axis=0)
            self.stress_raw_ = res.stress_before
            self.stress_ = res.stress_after
        return self

    def fit_transform(self, X, y=None) -> np.ndarray:
        """``fit(X).embedding_``: the training embedding itself."""
        return self.fit(X).embedding_

    def transform(self, X) -> np.ndarray:
        """Coordinates (M, n_components) of new points ``X`` (M, D): the embedder's
        out-of-sample extension of ``embedding_raw_`` (see ``_extend`` of each embedder), then
        the fitted AIC map y -> ybar + (y - ybar) A if ``aic`` was on in ``fit``."""
        check_is_fitted(self, "embedding_raw_")
        X = self._validate_points(X, reset=False)
        Y = self._extend(X)
        A = getattr(self, "aic_matrix_", None)
        if A is not None:
            Y = self.aic_center_ + (Y - self.aic_center_) @ A
        return Y
