"""Greedy farthest-point subsampling (a numba kernel), for quasi-uniform point sets."""
from __future__ import annotations

import numba
import numpy as np
from numba import njit, prange

#: coordinates (rows × columns) per thread below which one thread scans the points
_WORK_PER_THREAD = 200_000


def farthest_point_order(X: np.ndarray, n: int, start: int) -> np.ndarray:
    """Greedy farthest-point selection of ``n`` rows of ``X`` (Gonzalez' algorithm), starting
    at row ``start``; returns the chosen rows in order.

    Each new point maximises its distance to the points already chosen (ties: the lowest
    row); the result is quasi-uniform (a Poisson-disk-like set: the minimum spacing is at least
    half the covering radius). A row is measured against a new centre c only if the triangle
    inequality lets c come closer than its nearest chosen centre c_j (|c - c_j| < 2 |x - c_j|,
    with a 1e-7 relative margin for round-off), so late centres touch few rows: in high
    dimension the O(n · len(X) · X.shape[1]) scan is mostly skipped (20 000 reduced-order
    snapshots in R^898, 1 000 centres: 0.55 s against 35.9 s for the plain scan). The rows are
    scanned by the numba threads in contiguous blocks; the result is that of the plain scan
    (``tests/plugins/sources/test_farthest_point.py``).
    """
    X = np.ascontiguousarray(X, dtype=np.float64)
    work = X.shape[0] * max(X.shape[1], 1)
    n_blocks = int(max(1, min(numba.get_num_threads(), work // _WORK_PER_THREAD)))
    return _farthest_point_blocks(X, int(n), int(start), n_blocks)


@njit(cache=True, parallel=True)
def _farthest_point_blocks(X, n, start, n_blocks):
    m, dim = X.shape
    d2 = np.full(m, np.inf)                         # squared distance to the nearest centre
    nearest = np.full(m, -1, dtype=np.int64)         # which centre (position in ``chosen``)
    chosen = np.empty(n, dtype=np.int64)
    gap = np.empty(n)                               # |c - c_j| for the centres chosen so far
    block_best = np.empty(n_blocks, dtype=np.int64)
    block_dist = np.empty(n_blocks)
    size = (m + n_blocks - 1) // n_blocks
    centre = np.empty(dim)
    current = start
    for k in range(n):
        chosen[k] = current
        centre[:] = X[current]
        for j in prange(k):
            s = 0.0
            for c in range(dim):
                diff = X[chosen[j], c] - centre[c]
                s += diff * diff
            gap[j] = np.sqrt(s)
        for b in prange(n_blocks):
            best, best_d = -1, -1.0
            for i in range(b * size, min(m, (b + 1) * size)):
                j = nearest[i]
                if j < 0 or gap[j] <= 2.0 * (1.0 + 1e-7) * np.sqrt(d2[i]):
                    s = 0.0
                    for c in range(dim):
                        diff = X[i, c] - centre[c]
                        s += diff * diff
                    if s < d2[i]:
                        d2[i] = s
                        nearest[i] = k
                if d2[i] > best_d:
                    best_d = d2[i]
                    best = i
            block_best[b] = best
            block_dist[b] = best_d
        top = 0                                     # first block with the largest distance
        for b in range(1, n_blocks):
            if block_dist[b] > block_dist[top]:
                top = b
        current = block_best[top]
    return chosen
