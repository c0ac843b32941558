"""Node sets, dense conversions and finite differences shared by the approximant tests.

Tests get these functions through the ``ax`` fixture (``ax.dense(B, n)`` ...).
"""
from __future__ import annotations

import itertools
import sys

import numpy as np
import pytest


@pytest.fixture(scope="session")
def ax():
    return sys.modules[__name__]


def nonuniform_nodes(d: int, n: int, seed: int) -> np.ndarray:
    """n random nodes in [0, 1]^d, denser near the origin, plus the 2^d cube corners."""
    rng = np.random.default_rng(seed)
    inner = rng.random((n, d)) ** 1.5
    corners = np.array(list(itertools.product([0.0, 1.0], repeat=d)))
    return np.vstack([corners, inner])


def inside_points(d: int, m: int, seed: int) -> np.ndarray:
    """m points well inside the cube [0, 1]^d (hence well inside the hull of the nodes)."""
    return 0.35 + 0.3 * np.random.default_rng(seed + 1000).random((m, d))


def dense(B, n: int):
    """(values (m, n), gradients (m, n, d) or None, hessians (m, n, d, d) or None)."""
    m = B.n_points
    rows = np.repeat(np.arange(m), np.diff(B.indptr))
    P = np.zeros((m, n))
    P[rows, B.indices] = B.values
    G = H = None
    if B.gradients is not None:
        G = np.zeros((m, n, B.gradients.shape[1]))
        G[rows, B.indices] = B.gradients
    if B.hessians is not None:
        H = np.zeros((m, n) + B.hessians.shape[1:])
        H[rows, B.indices] = B.hessians
    return P, G, H


def finite_differences(model, x: np.ndarray, step: float):
    """4th-order central differences of values and gradients: (dP (m, n, d), dG (m, n, d, d))."""
    n = model.nodes_.shape[0]
    d = x.shape[1]
    dP = np.zeros((len(x), n, d))
    dG = np.zeros((len(x), n, d, d))
    for k in range(d):
        e = np.zeros(d)
        e[k] = step
        P2, G2, _ = dense(model.evaluate(x + 2 * e, order=1), n)
        P1, G1, _ = dense(model.evaluate(x + e, order=1), n)
        M1, H1, _ = dense(model.evaluate(x - e, order=1), n)
        M2, H2, _ = dense(model.evaluate(x - 2 * e, order=1), n)
        dP[:, :, k] = (-P2 + 8 * P1 - 8 * M1 + M2) / (12 * step)
        dG[:, :, :, k] = (-G2 + 8 * G1 - 8 * H1 + H2) / (12 * step)
    return dP, dG


def rel_err(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())
