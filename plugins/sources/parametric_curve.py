"""Shared machinery of the analytic curve generators (d = 1): arc-length sampling, exact
length and total squared curvature by quadrature of the parametrization.

A subclass sets ``closed`` and implements ``_span()`` (parameter interval [t0, t1]; for a
closed curve one period) and ``_derivatives(t)`` returning (γ, γ', γ'') at parameters t, each
(n, D). Points are placed by arc length s (structured: equally spaced, a closed curve half a
spacing off its seam, an open one with both end points; random: uniform in s, an open curve
keeping both end points so the sampled curve is the whole curve). The parameters returned
are the arc lengths s (n, 1).

Exact values: length L = ∫|γ'| dt and ∫κ² ds with κ² = (|γ'|²|γ''|² − (γ'·γ'')²)/|γ'|⁶,
integrated with the periodic trapezoidal rule for a closed curve (exponentially convergent
for smooth periodic integrands) and composite Gauss–Legendre for an open one.
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np

from .surface_source import SurfaceSource

#: parameter samples of the arc-length table and of the exact integrals
TABLE_SIZE = 8192


def squared_curvature(v: np.ndarray, acc: np.ndarray) -> np.ndarray:
    """κ² = (|γ'|²|γ''|² − (γ'·γ'')²)/|γ'|⁶ of a curve in any R^D, from γ' and γ'' (n, D)."""
    vv = np.einsum("ij,ij->i", v, v)
    aa = np.einsum("ij,ij->i", acc, acc)
    va = np.einsum("ij,ij->i", v, acc)
    return np.clip(vv * aa - va * va, 0.0, None) / vv**3


class ParametricCurve(SurfaceSource):
    """Base of the analytic curves; not a plugin by itself."""

    intrinsic_dim: ClassVar[int] = 1
    closed: ClassVar[bool] = True

    # -- to implement ---------------------------------------------------------------
    def _span(self) -> tuple[float, float]:  # pragma: no cover - overridden
        raise NotImplementedError

    def _derivatives(self, t: np.ndarray):  # pragma: no cover - overridden
        raise NotImplementedError

    # -- quadrature of the parametrization --------------------------------------------
    def _quadrature(self) -> tuple[np.ndarray, np.ndarray]:
        """Parameter nodes and weights integrating smooth functions of t over the span."""
        t0, t1 = self._span()
        if self.closed:
            t = t0 + (t1 - t0) * np.arange(TABLE_SIZE) / TABLE_SIZE
            return t, np.full(TABLE_SIZE, (t1 - t0) / TABLE_SIZE)
        x, w = np.polynomial.legendre.leggauss(8)
        edges = np.linspace(t0, t1, TABLE_SIZE // 8 + 1)
        half = np.diff(edges)[:, None] / 2.0
        t = (edges[:-1, None] + half * (x[None, :] + 1.0)).ravel()
        return t, (half * w[None, :]).ravel()

    def curve_integrals(self) -> dict[str, float]:
        """Exact (to round-off) length and ∫κ² ds of the curve."""
        t, w = self._quadrature()
        _, v, acc = self._derivatives(t)
        speed = np.linalg.norm(v, axis=1)
        return {"length": float(np.sum(w * speed)),
                "total_squared_curvature": float(np.sum(w * speed * squared_curvature(v, acc)))}

    def _parameters_at_arc_length(self, s: np.ndarray) -> np.ndarray:
        """t(s) by interpolating the cumulative arc-length table (trapezoid, TABLE_SIZE steps)."""
        t0, t1 = self._span()
        t = np.linspace(t0, t1, TABLE_SIZE + 1)
        speed = np.linalg.norm(self._derivatives(t)[1], axis=1)
        cum = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(t))])
        return np.interp(s * cum[-1], cum, t)

    def _sample(self, n, sampling, rng):
        """Points at arc-length fractions u ∈ [0, 1]; returns (points, arc lengths (n, 1))."""
        if sampling == "structured":
            u = (np.arange(n) + 0.5) / n if self.closed else np.arange(n) / (n - 1)
        else:
            u = np.sort(rng.uniform(0.0, 1.0, n))
            if not self.closed:
                u[0], u[-1] = 0.0, 1.0
        t = self._parameters_at_arc_length(u)
        length = self.curve_integrals()["length"]
        return self._derivatives(t)[0], (u * length)[:, None]

    def _exact(self):
        out = self.curve_integrals()
        out["euler_characteristic"] = 0 if self.closed else 1
        return out
