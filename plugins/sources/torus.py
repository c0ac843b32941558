"""The ring torus of revolution with major radius R and minor radius r (R > r > 0).

Parametrisation (u, v) ∈ [0, 2π)²: x = ((R + r cos v) cos u, (R + r cos v) sin u, r sin v),
area element dA = r (R + r cos v) du dv.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from .lattices import allocate_counts, staggered_rows
from .surface_source import COMMON_CONSTRAINTS, POSITIVE, SurfaceSource, require


def torus_points(R: float, r: float, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Cartesian points of the torus at parameters (u, v), radians."""
    rho = R + r * np.cos(v)
    return np.column_stack([rho * np.cos(u), rho * np.sin(u), r * np.sin(v)])


def torus_structured(n: int, R: float, r: float):
    """Area-aware structured lattice on the torus: exactly ``n`` points.

    Tube circles (rings) v_j are equally spaced in v, so the spacing r·Δv between rings is
    constant; the spacing h = sqrt(4π²Rr/n) sets their number; ring j gets a number of
    points proportional to its length 2π(R + r cos v_j) (largest remainder), equally
    spaced in u with a golden-ratio stagger between rings. Returns ``(u, v)``.
    """
    area = 4.0 * np.pi**2 * R * r
    h = np.sqrt(area / n)
    n_rings = int(min(n, max(3, round(2.0 * np.pi * r / h))))
    v_rings = 2.0 * np.pi * np.arange(n_rings) / n_rings
    counts = allocate_counts(n, R + r * np.cos(v_rings))
    ring, u = staggered_rows(counts, 2.0 * np.pi, periodic=True)
    return u, v_rings[ring]


def torus_random(n: int, R: float, r: float, rng: np.random.Generator):
    """Uniform w.r.t. area by rejection: (u, v) uniform, accept v with probability
    (R + r cos v)/(R + r). Returns exactly ``n`` parameter pairs ``(u, v)``."""
    us, vs, have = [], [], 0
    while have < n:
        m = int(1.3 * (n - have)) + 16
        u = rng.uniform(0.0, 2.0 * np.pi, m)
        v = rng.uniform(0.0, 2.0 * np.pi, m)
        keep = rng.uniform(0.0, R + r, m) < R + r * np.cos(v)
        us.append(u[keep])
        vs.append(v[keep])
        have += int(keep.sum())
    return np.concatenate(us)[:n], np.concatenate(vs)[:n]


class Torus(SurfaceSource):
    """Ring torus with major radius ``R`` and tube radius ``r`` (R > r).

    structured: rings equally spaced around the tube, points per ring proportional to the
    ring length. random: uniform w.r.t. area (rejection sampling).
    Exact: area 4π²Rr, χ = 0, genus 1, Willmore energy ∫(κ1+κ2)² dA = 4π² a²/sqrt(a²-1)
    with a = R/r (π² a²/sqrt(a²-1) with the mean-curvature convention), ∫K dA = 0.
    """

    @dataclass
    class Config:
        n_points: int = 1000
        sampling: str = "structured"
        R: float = 1.0
        r: float = 0.5
        n_markers: Optional[int] = None

        # R: major radius, r: tube radius, r < R (checked with both)
        parameter_constraints: ClassVar[dict[str, list]] = {**COMMON_CONSTRAINTS,
                                                            "R": POSITIVE, "r": POSITIVE}

    description: ClassVar[str] = "Ring torus of radii R > r (area-aware lattice or uniform random)."
    name: ClassVar[str] = "torus"

    def __init__(self, *, n_points: int = 1000, sampling: str = "structured",
                 R: float = 1.0, r: float = 0.5, n_markers: Optional[int] = None):
        self.n_points = n_points
        self.sampling = sampling
        self.R = R
        self.r = r
        self.n_markers = n_markers

    def _check(self) -> None:
        require(self.r < self.R, "r", self.r, f"must be smaller than R={self.R} (ring torus)",
                "Choose r < R, e.g. R=1.0, r=0.5.")

    def _sample(self, n, sampling, rng):
        R, r = float(self.R), float(self.r)
        if sampling == "structured":
            u, v = torus_structured(n, R, r)
        else:
            u, v = torus_random(n, R, r, rng)
        return torus_points(R, r, u, v), np.column_stack([u, v])

    def _exact(self):
        R, r = float(self.R), float(self.r)
        a = R / r
        return {
            "area": 4.0 * np.pi**2 * R * r,
            "euler_characteristic": 0,
            "genus": 1,
            "willmore_energy": 4.0 * np.pi**2 * a**2 / np.sqrt(a**2 - 1.0),
            "total_gaussian_curvature": 0.0,
        }
