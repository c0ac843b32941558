"""The classical swiss roll (thesis Fig. 2): x = (t cos t, y, t sin t), t ∈ [1.5π, 4.5π].

Arc length along the spiral from t = 1.5π: s(t) = S(t) - S(1.5π) with
S(t) = (t·sqrt(1 + t²) + asinh t)/2; the surface is developable (K = 0) and (s, y) are
isometric coordinates, so the area is s(4.5π)·height.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.constraints import Interval

from .lattices import allocate_counts, rows_for_rectangle, staggered_rows
from .surface_source import COMMON_CONSTRAINTS, POSITIVE, SurfaceSource

T_MIN, T_MAX = 1.5 * np.pi, 4.5 * np.pi


def spiral_arc(t: np.ndarray) -> np.ndarray:
    """S(t) = ∫_0^t sqrt(1 + τ²) dτ, the arc length of the spiral (t cos t, t sin t)."""
    return 0.5 * (t * np.sqrt(1.0 + t * t) + np.arcsinh(t))


def spiral_parameter(s: np.ndarray, t_min: float = T_MIN) -> np.ndarray:
    """Invert s = S(t) - S(t_min) for t by Newton's method (S' = sqrt(1 + t²) > 0)."""
    target = np.asarray(s, dtype=np.float64) + spiral_arc(t_min)
    t = np.full_like(target, t_min) + s / np.sqrt(1.0 + t_min**2)
    for _ in range(50):
        step = (spiral_arc(t) - target) / np.sqrt(1.0 + t * t)
        t -= step
        if np.max(np.abs(step), initial=0.0) < 1e-14 * T_MAX:
            break
    return t


class SwissRoll(SurfaceSource):
    """Swiss roll, t ∈ [1.5π, 4.5π], y ∈ [0, height]; optional Gaussian noise.

    structured: rows along the spiral, equally spaced in arc length and height (exactly
    n_points, staggered). random: uniform w.r.t. area (arc length and y uniform).
    ``noise`` is the standard deviation of isotropic Gaussian noise added to the points
    (length units); parameters stay the noise-free (s, y).
    Exact: area L·height with L = S(4.5π) - S(1.5π), χ = 1, genus 0, ∫K dA = 0.
    """

    @dataclass
    class Config:
        n_points: int = 1000
        sampling: str = "random"
        height: float = 21.0
        noise: float = 0.0
        n_markers: Optional[int] = None

        # height: extent along y; noise: standard deviation of the Gaussian noise
        parameter_constraints: ClassVar[dict[str, list]] = {
            **COMMON_CONSTRAINTS, "height": POSITIVE, "noise": [Interval(float, 0, None)]}

    description: ClassVar[str] = "Classical swiss roll, t in [1.5π, 4.5π] (thesis Fig. 2)."
    name: ClassVar[str] = "swiss_roll"

    def __init__(self, *, n_points: int = 1000, sampling: str = "random",
                 height: float = 21.0, noise: float = 0.0, n_markers: Optional[int] = None):
        self.n_points = n_points
        self.sampling = sampling
        self.height = height
        self.noise = noise
        self.n_markers = n_markers

    @property
    def length(self) -> float:
        return float(spiral_arc(T_MAX) - spiral_arc(T_MIN))

    def _sample(self, n, sampling, rng):
        L, H = self.length, float(self.height)
        if sampling == "structured":
            n_rows = rows_for_rectangle(n, L, H)
            counts = allocate_counts(n, np.ones(n_rows))
            row, s = staggered_rows(counts, L, periodic=False)
            y = H * (row + 0.5) / n_rows
        else:
            s = rng.uniform(0.0, L, n)
            y = rng.uniform(0.0, H, n)
        t = spiral_parameter(s)
        X = np.column_stack([t * np.cos(t), y, t * np.sin(t)])
        if self.noise > 0:
            X = X + self.noise * rng.standard_normal(X.shape)
        return X, np.column_stack([s, y])

    def _exact(self):
        return {
            "area": self.length * float(self.height),
            "length": self.length,
            "euler_characteristic": 1,
            "genus": 0,
            "total_gaussian_curvature": 0.0,
        }
