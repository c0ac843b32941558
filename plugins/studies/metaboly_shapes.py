"""Shape descriptors of axisymmetric cells (stage 4 of the metaboly pipeline).

Arroyo, Heltai, Millán & DeSimone, PNAS 109 (2012) 17874, "Shape analysis": each generating
curve (r, z), top pole to bottom pole, is fitted by a cubic B-spline with ``n_intervals``
(20–30) knot intervals in the chord-length parameter by least squares
(``scipy.interpolate.make_lsq_spline``), with r made odd about the poles by mirroring the
curve across the axis before the fit, and resampled at ``n_points`` equal arclength
stations: each frame a point of R^D, D = 2 n_points (the descriptor). Area and volume of
the body of revolution, S = 2π ∫ r dℓ and V = π ∫ r² |dz|, by the trapezoidal rule on the
resampled curve; reduced volume v = 6√π V / S^{3/2} (1 for a sphere).
"""
from __future__ import annotations

import numpy as np
from scipy.interpolate import make_lsq_spline


def _chord(P):
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
    return s / s[-1]


def fit_curve(curve: np.ndarray, n_intervals: int = 24, n_points: int = 101) -> np.ndarray:
    """The generating curve (m, 2) refitted by a cubic least-squares B-spline with
    ``n_intervals`` knot intervals on the physical half and resampled at ``n_points``
    equal-arclength stations (poles on the axis)."""
    P = np.asarray(curve, dtype=np.float64)
    t = _chord(P)
    # mirror across the axis so that the fit is odd in r about both poles
    tt = np.concatenate([-t[:0:-1], t, 2.0 - t[-2::-1]])
    PP = np.concatenate([P[:0:-1] * [-1, 1], P, P[-2::-1] * [-1, 1]])
    k = 3
    inner = np.linspace(-1.0, 2.0, 3 * n_intervals + 1)
    knots = np.concatenate([[inner[0]] * k, inner, [inner[-1]] * k])
    spl = make_lsq_spline(tt, PP, knots, k=k)
    u = np.linspace(0.0, 1.0, 20 * n_points)
    X = spl(u)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(X, axis=0), axis=1))])
    st = np.linspace(0.0, s[-1], n_points)
    out = np.column_stack([np.interp(st, s, X[:, 0]), np.interp(st, s, X[:, 1])])
    out[[0, -1], 0] = 0.0
    return out


def area_volume(curve: np.ndarray) -> tuple[float, float]:
    """(S, V) of the body of revolution of ``curve`` (µm², µm³)."""
    r, z = np.asarray(curve, dtype=np.float64).T
    dl = np.hypot(np.diff(r), np.diff(z))
    S = 2.0 * np.pi * np.sum(0.5 * (r[1:] + r[:-1]) * dl)
    V = -np.pi * np.sum(0.5 * (r[1:] ** 2 + r[:-1] ** 2) * np.diff(z))
    return float(S), float(abs(V))


def reduced_volume(S: float, V: float) -> float:
    """v = 6√π V / S^{3/2}."""
    return float(6.0 * np.sqrt(np.pi) * V / S ** 1.5)


def descriptors(curves, n_intervals: int = 24, n_points: int = 101) -> dict:
    """Fitted curves (K, n_points, 2), descriptor vectors (K, 2 n_points), area, volume and
    reduced volume per frame, and the area deviation max |S − S̄|/S̄ over the sequence."""
    fitted = np.stack([fit_curve(c, n_intervals, n_points) for c in curves])
    SV = np.array([area_volume(c) for c in fitted])
    S, V = SV[:, 0], SV[:, 1]
    return {"curves": fitted, "vectors": fitted.reshape(len(fitted), -1), "area": S,
            "volume": V, "reduced_volume": 6.0 * np.sqrt(np.pi) * V / S ** 1.5,
            "area_deviation": float(np.abs(S / S.mean() - 1.0).max())}
