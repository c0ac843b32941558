"""Comparison of a recovered stroke with the ground truth of a synthetic sequence.

The recovered stroke's phase 0 is where its first embedding coordinate rises through its
median, an arbitrary point of the true stroke, and its "top" pole is the one the first kept
frame showed on top: the truth is aligned by the phase offset δ (a grid of ``n_grid``
offsets, then a parabola through the best three) and the pole flip that minimise the shape
distance. Shape distance between two curves resampled alike (:mod:`.metaboly_shapes`): the
largest distance between corresponding stations; ``shape_error`` is its maximum over the
phases divided by the body length (pole to pole, the mean over the true stroke).
"""
from __future__ import annotations

import numpy as np


def flip(curve: np.ndarray) -> np.ndarray:
    """The same body seen with the other pole on top: z → −z, stations reversed."""
    return (curve * [1.0, -1.0])[::-1]


def _distance(A, B):
    return np.linalg.norm(A - B, axis=-1).max(axis=-1)          # per phase


def align(recovered: np.ndarray, truth_at, phases: np.ndarray, fit, n_grid: int = 200):
    """(δ, flipped, true curves at phases + δ): the alignment of the truth to the recovered
    curves (K, n, 2) sampled at ``phases``; ``truth_at(phase) -> curve``, ``fit(curve)`` the
    resampling used for the recovered curves."""
    grid = np.arange(n_grid) / n_grid
    table = np.stack([fit(truth_at(p)) for p in grid])            # (n_grid, n, 2)
    best = (np.inf, 0.0, False)
    for flipped in (False, True):
        T = np.stack([flip(c) for c in table]) if flipped else table
        for j, d in enumerate(grid):
            idx = np.rint((np.mod(phases + d, 1.0)) * n_grid).astype(int) % n_grid
            err = _distance(recovered, T[idx]).max()
            if err < best[0]:
                best = (err, d, flipped)
    _, d0, flipped = best

    def curves(delta):
        out = np.stack([fit(truth_at(np.mod(p + delta, 1.0))) for p in phases])
        return np.stack([flip(c) for c in out]) if flipped else out

    h = 1.0 / n_grid
    e = [_distance(recovered, curves(d0 + s * h)).max() for s in (-1, 0, 1)]
    den = e[0] - 2 * e[1] + e[2]
    d = d0 + (0.5 * h * (e[0] - e[2]) / den if den > 0 else 0.0)
    return float(np.mod(d, 1.0)), flipped, curves(d)


def shape_error(recovered: np.ndarray, aligned_truth: np.ndarray) -> float:
    """max over phases of the largest station distance / mean true body length."""
    length = np.mean(np.ptp(aligned_truth[..., 1], axis=1))
    return float(_distance(recovered, aligned_truth).max() / length)


def true_period(truth: dict, t0: float, t1: float) -> float:
    """The truth's mean period over [t0, t1]: elapsed time over elapsed true cycles."""
    starts = np.asarray(truth["cycle_starts"], dtype=np.float64)
    if "cycle_durations" in truth:          # the end of the last cycle
        starts = np.append(starts, starts[-1] + np.asarray(truth["cycle_durations"])[-1])

    def cycles(t):
        k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(starts) - 2)
        return k + (t - starts[k]) / (starts[k + 1] - starts[k])

    return float((t1 - t0) / (cycles(t1) - cycles(t0)))
