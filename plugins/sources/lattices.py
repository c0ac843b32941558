"""Deterministic quasi-uniform point lattices used by the structured samplers.

Pure functions on arrays; no randomness. Lengths are in the units of the caller.
"""
from __future__ import annotations

import numpy as np

#: 1/φ, the golden-ratio conjugate; i·(1/φ) mod 1 is the most evenly spread 1-D sequence.
GOLDEN_FRACTION = (np.sqrt(5.0) - 1.0) / 2.0


def fibonacci_band(n: int, z_lo: float, z_hi: float, phi_span: float = 2.0 * np.pi):
    """Fibonacci (golden-spiral) lattice on a band of the unit sphere.

    Archimedes: on a sphere the area between two heights is proportional to their
    difference, so heights equally spaced in ``[z_lo, z_hi]`` and azimuths advancing by
    the golden fraction of ``phi_span`` give a quasi-uniform, equal-area lattice.

    Returns ``(z, phi)`` arrays of length ``n``; ``z`` descends from ``z_hi`` to ``z_lo``.
    """
    i = np.arange(n, dtype=np.float64)
    z = z_hi - (z_hi - z_lo) * (i + 0.5) / n
    phi = phi_span * np.mod(i * GOLDEN_FRACTION, 1.0)
    return z, phi


def allocate_counts(n: int, weights: np.ndarray) -> np.ndarray:
    """Split ``n`` into integer counts proportional to ``weights`` (largest remainder).

    The counts sum exactly to ``n`` and differ from ``n·w/Σw`` by less than one.
    """
    w = np.asarray(weights, dtype=np.float64)
    share = n * w / w.sum()
    counts = np.floor(share).astype(np.int64)
    missing = n - int(counts.sum())
    if missing > 0:
        order = np.argsort(-(share - counts), kind="stable")
        counts[order[:missing]] += 1
    return counts


def staggered_rows(counts: np.ndarray, span: float, periodic: bool) -> tuple[np.ndarray, np.ndarray]:
    """Positions along rows: row ``j`` gets ``counts[j]`` equally spaced points in ``[0, span)``.

    Rows are offset by the golden fraction of one spacing so neighbouring rows do not line
    up (a staggered, near-hexagonal arrangement). For non-periodic rows the points sit at
    cell centres ``(k + 1/2)·span/m``, half a spacing from both ends.

    Returns ``(row_index, position)`` of length ``counts.sum()``.
    """
    rows, positions = [], []
    for j, m in enumerate(counts):
        if m == 0:
            continue
        k = np.arange(m, dtype=np.float64)
        if periodic:
            shift = np.mod(j * GOLDEN_FRACTION, 1.0)
            pos = span * np.mod((k + shift) / m, 1.0)
        else:
            pos = span * (k + 0.5) / m
        rows.append(np.full(m, j))
        positions.append(pos)
    return np.concatenate(rows), np.concatenate(positions)


def rows_for_rectangle(n: int, length: float, width: float) -> int:
    """Number of rows (along ``width``) for ``n`` points on a ``length × width`` rectangle
    with equal spacing in both directions: spacing h = sqrt(length·width/n)."""
    h = np.sqrt(length * width / n)
    return int(max(1, min(n, round(width / h))))
