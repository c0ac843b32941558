"""Intrinsic-dimension estimators, thesis §2.3 (L63-125) and Fig. 3 (L1840-1880).

Pure functions returning arrays (curves to plot or read):

* :func:`correlation_dimension` - C(eps), the mean number of other points within eps, and
  d_corr(eps) = d log C / d log eps (Fig. 3A).
* :func:`local_pca_residual_variance` - for windows of the ``n_window`` nearest points of each
  point, 1 - sum_{i<=d} lambda_i / sum_i lambda_i, as mean and percentiles across points for
  every d (Fig. 3B).
* :func:`pca_reconstruction_error` - thesis Eq. (1), e_a = |xbar + V V^T (x_a - xbar) - x_a| / |x_a|
  with V the d leading global principal directions, mean and percentiles for every d (Fig. 3C).
* :func:`local_pca_dimension` - per-point smallest d keeping a given fraction of the local variance.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def correlation_dimension(X, scales=None, n_scales: int = 40):
    """Return ``(scales, C, d_corr)``, arrays of the same length.

    ``scales``: radii eps (units of X); default: ``n_scales`` log-spaced values between the
    median nearest-neighbour distance and the diameter of the bounding box.
    C(eps) = (number of ordered pairs a != b with |x_a - x_b| <= eps) / N.
    """
    X = np.asarray(X, float)
    tree = cKDTree(X)
    if scales is None:
        nn = tree.query(X, 2)[0][:, 1]
        lo = np.median(nn)
        hi = np.linalg.norm(X.max(axis=0) - X.min(axis=0))
        scales = np.geomspace(lo, hi, n_scales)
    scales = np.asarray(scales, float)
    counts = tree.count_neighbors(tree, scales).astype(float) - X.shape[0]   # drop self pairs
    C = counts / X.shape[0]
    with np.errstate(divide="ignore", invalid="ignore"):
        d_corr = np.gradient(np.log(np.maximum(C, 1e-300)), np.log(scales))
    return scales, C, d_corr


def _percentiles(values: np.ndarray, percentiles) -> tuple[np.ndarray, np.ndarray]:
    return values.mean(axis=0), np.percentile(values, percentiles, axis=0)


def local_pca_eigenvalues(X, n_window: int = 20) -> np.ndarray:
    """(N, D) eigenvalues (descending) of the covariance of each point's ``n_window`` nearest."""
    X = np.asarray(X, float)
    _, nb = cKDTree(X).query(X, n_window)
    W = X[nb] - X[nb].mean(axis=1, keepdims=True)          # (N, n_window, D)
    C = np.einsum("nkD,nkE->nDE", W, W) / n_window
    return np.linalg.eigvalsh(C)[:, ::-1]


def local_pca_residual_variance(X, n_window: int = 20, percentiles=(25, 75)):
    """Return ``(dims, mean, pct)``: 1 - cumulative explained variance fraction for d = 1..D.

    ``mean`` has shape (D,), ``pct`` shape (len(percentiles), D), across points.
    """
    lam = np.maximum(local_pca_eigenvalues(X, n_window), 0.0)
    frac = np.cumsum(lam, axis=1) / lam.sum(axis=1, keepdims=True)
    resid = np.clip(1.0 - frac, 0.0, 1.0)
    mean, pct = _percentiles(resid, percentiles)
    return np.arange(1, lam.shape[1] + 1), mean, pct


def local_pca_dimension(X, n_window: int = 20, fraction: float = 0.95) -> np.ndarray:
    """(N,) int: smallest d with sum_{i<=d} lambda_i >= ``fraction`` sum_i lambda_i locally."""
    lam = np.maximum(local_pca_eigenvalues(X, n_window), 0.0)
    frac = np.cumsum(lam, axis=1) / lam.sum(axis=1, keepdims=True)
    return 1 + np.argmax(frac >= fraction - 1e-12, axis=1)


def pca_reconstruction_error(X, dims=None, percentiles=(25, 75)):
    """Return ``(dims, mean, pct)`` of thesis Eq. (1) for each d in ``dims`` (default 1..D)."""
    X = np.asarray(X, float)
    xbar = X.mean(axis=0)
    Xc = X - xbar
    _, _, Vt = np.linalg.svd(Xc, full_matrices=False)
    dims = np.arange(1, X.shape[1] + 1) if dims is None else np.asarray(dims, int)
    norm = np.linalg.norm(X, axis=1)
    norm = np.where(norm > 0, norm, 1.0)
    errs = np.empty((X.shape[0], dims.size))
    for c, d in enumerate(dims):
        V = Vt[:d].T
        errs[:, c] = np.linalg.norm(Xc @ V @ V.T - Xc, axis=1) / norm
    mean, pct = _percentiles(errs, percentiles)
    return dims, mean, pct
