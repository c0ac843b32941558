"""Greedy farthest-point subsampling (a numba kernel), for quasi-uniform point sets."""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def farthest_point_order(X: np.ndarray, n: int, start: int) -> np.ndarray:
    """Greedy farthest-point selection of ``n`` rows of ``X`` (Gonzalez' algorithm).

    Each new point maximises its distance to the points already chosen; the result is
    quasi-uniform (a Poisson-disk-like set: the minimum spacing is at least half the covering
    radius). Cost O(n · len(X)).
    """
    m = X.shape[0]
    d2 = np.full(m, np.inf)
    chosen = np.empty(n, dtype=np.int64)
    current = start
    for k in range(n):
        chosen[k] = current
        best, best_d = 0, -1.0
        for i in range(m):
            s = 0.0
            for c in range(X.shape[1]):
                diff = X[i, c] - X[current, c]
                s += diff * diff
            if s < d2[i]:
                d2[i] = s
            if d2[i] > best_d:
                best_d = d2[i]
                best = i
        current = best
    return chosen
