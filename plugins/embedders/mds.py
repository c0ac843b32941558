"""Classical (Torgerson) MDS of a distance matrix, full and landmark versions (thesis §2.1-2.2).

Isomap = classical MDS of geodesic distances. Landmark MDS (de Silva & Tenenbaum 2003) embeds
L landmarks by classical MDS and places every other point by distance triangulation; memory
O(L N), used to seed NLIE on large point sets.
"""
from __future__ import annotations

import numpy as np


def _orient(Y: np.ndarray) -> np.ndarray:
    """Deterministic signs: the entry of largest magnitude of each column is positive."""
    i = np.argmax(np.abs(Y), axis=0)
    s = np.sign(Y[i, np.arange(Y.shape[1])])
    s[s == 0] = 1.0
    return Y * s


def double_centered_gram_inplace(D: np.ndarray) -> np.ndarray:
    """Turn a distance matrix into B = -1/2 J D^2 J (J the centring projector), in place."""
    np.square(D, out=D)
    D *= -0.5
    m = D.mean(axis=1)
    total = m.mean()
    D -= m[:, None]
    D -= m[None, :]
    D += total
    return D


def top_eigenpairs(B: np.ndarray, d: int, seed: int = 0):
    """The d largest eigenvalues (descending) and eigenvectors of the symmetric matrix B."""
    n = B.shape[0]
    if n <= 300:
        w, V = np.linalg.eigh(B)
        return w[::-1][:d], V[:, ::-1][:, :d]
    from scipy.sparse.linalg import eigsh

    v0 = np.random.default_rng(seed).uniform(-1, 1, n)
    w, V = eigsh(B, k=d, which="LA", v0=v0, tol=0.0)
    order = np.argsort(w)[::-1]
    return w[order], V[:, order]


def classical_mds(D: np.ndarray, d: int, *, overwrite: bool = False):
    """Classical MDS of an (N, N) distance matrix: Y = V_d Lambda_d^{1/2}.

    Returns ``(Y, eigenvalues)``; negative eigenvalues (non-Euclidean distances) give zero columns.
    With ``overwrite`` the matrix ``D`` is destroyed (saves one N x N array).
    """
    B = double_centered_gram_inplace(D if overwrite else D.copy())
    w, V = top_eigenpairs(B, d)
    Y = V * np.sqrt(np.maximum(w, 0.0))
    return _orient(Y), w


def landmark_mds(D_land: np.ndarray, landmarks: np.ndarray, d: int):
    """Landmark MDS: ``D_land`` (L, N) distances from the L ``landmarks`` to all N points.

    Landmarks are embedded by classical MDS of their (L, L) block; point x is placed at
    y = -1/2 L^# (delta_x^2 - mean_landmarks delta^2), L^# = V_d Lambda_d^{-1/2} transposed.
    """
    Dll = D_land[:, landmarks]
    B = double_centered_gram_inplace(Dll.copy())
    w, V = top_eigenpairs(B, d)
    w = np.maximum(w, 1e-12 * w.max())
    pinv = V / np.sqrt(w)                         # (L, d)
    D2 = np.square(D_land)
    mean_sq = (np.square(Dll)).mean(axis=1)       # (L,)
    Y = -0.5 * (D2 - mean_sq[:, None]).T @ pinv   # (N, d)
    Y -= Y.mean(axis=0)
    return _orient(Y)
