"""The round sphere of radius R (thesis Fig. 4A; Willmore study, thesis L1085)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from .lattices import fibonacci_band
from .surface_source import COMMON_CONSTRAINTS, POSITIVE, SurfaceSource


def spherical_to_cartesian(radius: float, z_unit: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Points ``R (sinθ cosφ, sinθ sinφ, cosθ)`` from ``cosθ = z_unit`` and azimuth ``phi``."""
    s = np.sqrt(np.clip(1.0 - z_unit**2, 0.0, None))
    return radius * np.column_stack([s * np.cos(phi), s * np.sin(phi), z_unit])


def sphere_parameters(z_unit: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Intrinsic coordinates (polar angle θ ∈ [0, π], azimuth φ ∈ [0, 2π)), radians."""
    return np.column_stack([np.arccos(np.clip(z_unit, -1.0, 1.0)), np.mod(phi, 2 * np.pi)])


class Sphere(SurfaceSource):
    """Sphere of radius ``radius`` centred at the origin, N points in R^3.

    structured: Fibonacci (golden-spiral) lattice, equal-area and quasi-uniform.
    random: independent points uniform w.r.t. area (normalised Gaussian vectors).
    Exact: area 4πR², χ = 2, genus 0, Willmore energy ∫H² dA = 16π with H = κ1 + κ2
    (thesis L1085; 4π with H = (κ1+κ2)/2), total Gaussian curvature 4π.
    """

    @dataclass
    class Config:
        n_points: int = 1000
        sampling: str = "structured"
        radius: float = 1.0
        n_markers: Optional[int] = None

        parameter_constraints: ClassVar[dict[str, list]] = {**COMMON_CONSTRAINTS,
                                                            "radius": POSITIVE}

    description: ClassVar[str] = "Round sphere of given radius (Fibonacci lattice or uniform random)."
    name: ClassVar[str] = "sphere"

    def __init__(self, *, n_points: int = 1000, sampling: str = "structured",
                 radius: float = 1.0, n_markers: Optional[int] = None):
        self.n_points = n_points
        self.sampling = sampling
        self.radius = radius
        self.n_markers = n_markers

    def _sample(self, n, sampling, rng):
        if sampling == "structured":
            z, phi = fibonacci_band(n, -1.0, 1.0)
        else:
            g = rng.standard_normal((n, 3))
            g /= np.linalg.norm(g, axis=1, keepdims=True)
            z, phi = g[:, 2], np.arctan2(g[:, 1], g[:, 0])
        return spherical_to_cartesian(self.radius, z, phi), sphere_parameters(z, phi)

    def _exact(self):
        R = float(self.radius)
        return {
            "area": 4.0 * np.pi * R**2,
            "radius": R,
            "euler_characteristic": 2,
            "genus": 0,
            "willmore_energy": 16.0 * np.pi,
            "total_gaussian_curvature": 4.0 * np.pi,
        }
