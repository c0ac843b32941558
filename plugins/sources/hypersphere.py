"""The round n-sphere S^n of radius R in R^(n+1) (default n = 3: a 3-manifold in R^4)."""
from __future__ import annotations

from dataclasses import dataclass
from math import gamma as gamma_function
from typing import ClassVar, Optional

import numpy as np

from pointatlas.constraints import Interval
from pointatlas.stores_config import stores_config

from .lattices import fibonacci_band
from .surface_source import COMMON_CONSTRAINTS, POSITIVE, SurfaceSource, require

#: ψ⁴ = ψ + 4: the second irrational of the super-Fibonacci spiral on S^3 (Alexa, CVPR 2022)
SUPER_FIBONACCI_PSI = 1.533751168755204288118041


def sphere_volume(n: int, radius: float) -> float:
    """n-volume of S^n of radius R: 2π^((n+1)/2) / Γ((n+1)/2) · R^n (2πR, 4πR², 2π²R³, ...)."""
    return 2.0 * np.pi ** ((n + 1) / 2.0) / gamma_function((n + 1) / 2.0) * radius**n


def super_fibonacci_s3(n: int) -> np.ndarray:
    """Quasi-uniform, equal-volume spiral of n unit vectors on S^3 ⊂ R^4.

    In coordinates x = (r sin α, r cos α, ρ sin β, ρ cos β), r² + ρ² = 1, the volume of S^3
    is uniform in (r², α, β); point i takes r² = (i + ½)/n and advances α, β by the
    irrationals 1/√2 and 1/ψ (ψ⁴ = ψ + 4) of a full turn, which spreads them evenly.
    """
    s = np.arange(n, dtype=np.float64) + 0.5
    r = np.sqrt(s / n)
    rho = np.sqrt(1.0 - s / n)
    alpha = 2.0 * np.pi * s / np.sqrt(2.0)
    beta = 2.0 * np.pi * s / SUPER_FIBONACCI_PSI
    return np.column_stack([r * np.sin(alpha), r * np.cos(alpha),
                            rho * np.sin(beta), rho * np.cos(beta)])


def hyperspherical_angles(x: np.ndarray) -> np.ndarray:
    """Angles (θ_1, …, θ_{n−1} ∈ [0, π], θ_n ∈ [0, 2π)) of unit vectors x (m, n + 1), with
    x_1 = cos θ_1, x_2 = sin θ_1 cos θ_2, …, x_{n+1} = sin θ_1 ⋯ sin θ_{n−1} sin θ_n."""
    n = x.shape[1] - 1
    tail = np.sqrt(np.cumsum(x[:, ::-1] ** 2, axis=1)[:, ::-1])  # |(x_k, …, x_{n+1})|
    ang = np.empty((x.shape[0], n))
    for k in range(n - 1):
        ang[:, k] = np.arctan2(tail[:, k + 1], x[:, k])
    ang[:, n - 1] = np.mod(np.arctan2(x[:, n], x[:, n - 1]), 2.0 * np.pi)
    return ang


@stores_config
class Hypersphere(SurfaceSource):
    """Round sphere S^dim of radius ``radius`` centred at the origin of R^(dim+1).

    structured: quasi-uniform lattices for dim ≤ 3 (equally spaced circle, Fibonacci sphere,
    super-Fibonacci spiral on S^3); random: normalised Gaussian vectors (uniform, any dim).
    Exact: ``volume`` (the dim-volume; 2π²R³ for S^3), principal curvatures 1/R, mean
    curvature H = dim/R (sum, thesis convention), ∫H² = dim²/R²·volume, scalar curvature
    dim(dim − 1)/R² and its integral, Euler characteristic 1 + (−1)^dim.
    """

    @dataclass
    class Config:
        n_points: int = 2000
        sampling: str = "structured"
        radius: float = 1.0
        dim: int = 3
        n_markers: Optional[int] = None

        # dim: intrinsic dimension n (ambient R^(n+1)); structured sampling needs n <= 3
        parameter_constraints: ClassVar[dict[str, list]] = {
            **COMMON_CONSTRAINTS, "radius": POSITIVE, "dim": [Interval(int, 1, None)]}

    description: ClassVar[str] = "Round n-sphere S^n in R^(n+1) (default S^3 in R^4, d = 3)."
    name: ClassVar[str] = "hypersphere"

    @property
    def intrinsic_dim(self) -> int:  # type: ignore[override]
        return int(self.dim)

    def _check(self) -> None:
        d = self.dim
        require(self.sampling == "random" or d <= 3, "dim", d,
                "structured sampling exists for dim <= 3",
                "Use sampling='random' for higher-dimensional spheres.")

    def _sample(self, n, sampling, rng):
        d = int(self.dim)
        if sampling == "random":
            x = rng.standard_normal((n, d + 1))
            x /= np.linalg.norm(x, axis=1, keepdims=True)
        elif d == 1:
            t = 2.0 * np.pi * (np.arange(n) + 0.5) / n
            x = np.column_stack([np.cos(t), np.sin(t)])
        elif d == 2:
            z, phi = fibonacci_band(n, -1.0, 1.0)
            s = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
            x = np.column_stack([z, s * np.cos(phi), s * np.sin(phi)])
        else:
            x = super_fibonacci_s3(n)
        return float(self.radius) * x, hyperspherical_angles(x)

    def _exact(self):
        d, R = int(self.dim), float(self.radius)
        vol = sphere_volume(d, R)
        out = {"volume": vol, "radius": R, "mean_curvature": d / R,
               "mean_curvature_squared_integral": (d / R) ** 2 * vol,
               "scalar_curvature": d * (d - 1) / R**2,
               "total_scalar_curvature": d * (d - 1) / R**2 * vol,
               "euler_characteristic": 1 + (-1) ** d}
        out[{1: "length", 2: "area"}.get(d, "volume")] = vol
        return out
