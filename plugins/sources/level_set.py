"""Points on an implicit surface F(x) = 0: Newton projection and near-surface candidates.

Shared by the implicit sources (connected_pipes, open_pipes). ``value_gradient(X)`` returns
F (n,) and ∇F (n, 3) at the rows of X (length units).
"""
from __future__ import annotations

from typing import Callable, Optional

import numpy as np


def project_to_level_set(X, value_gradient: Callable, tol: float, max_iter: int) -> np.ndarray:
    """Newton steps along the gradient, x ← x − F ∇F / |∇F|², until max |F| ≤ tol."""
    X = np.array(X, dtype=np.float64)
    for _ in range(max_iter):
        F, G = value_gradient(X)
        if np.max(np.abs(F), initial=0.0) <= tol:
            break
        X -= (F / np.einsum("ij,ij->i", G, G))[:, None] * G
    return X


def near_level_set(draw: Callable, n: int, value_gradient: Callable, half_width: float,
                   min_batch: int, per_missing: int,
                   accept: Optional[Callable] = None) -> np.ndarray:
    """n box samples from ``draw(m)`` within |F|/|∇F| < half_width of the surface (and
    ``accept(C)`` if given), drawn in batches of max(min_batch, per_missing·missing).

    Uniform samples in a symmetric shell project to a density uniform w.r.t. area up to
    O(half_width²·curvature²) (the linear term 2H·distance of the volume element cancels).
    """
    out, have = [], 0
    while have < n:
        C = draw(max(min_batch, per_missing * (n - have)))
        F, G = value_gradient(C)
        ok = np.abs(F) < half_width * np.linalg.norm(G, axis=1)
        if accept is not None:
            ok &= accept(C)
        out.append(C[ok])
        have += int(ok.sum())
    return np.concatenate(out)[:n]
