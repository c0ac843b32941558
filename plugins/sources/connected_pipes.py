"""A closed smooth surface of genus 2: a tube around the lemniscate of Bernoulli.

Stands in for the "connected pipes" of the thesis (L583, L2557: a shell of complex
topology that admits no single parametric domain). It is the level set

    F(x) = g(x, y)² + z² - c = 0,   g(x, y) = (x² + y²)² - x² + y²,

in units of ``scale``: g = 0 is the figure-eight lemniscate r² = cos 2θ, and F = 0 a thin
closed tube around it (half-thickness √c in z). g has exactly three critical points,
(0, 0) with g = 0 and (±1/√2, 0) with g = -1/4, so for 0 < c < 1/16 the gradient
∇F = (2g ∂g/∂x, 2g ∂g/∂y, 2z) never vanishes on F = 0 (smooth surface) and both lobes
keep a hole (|g| > √c near their centres): the surface has genus 2, χ = -2.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from .surface_source import COMMON_CONSTRAINTS, SurfaceSource, require, require_positive

#: Candidates per output point for the structured (farthest-point) selection.
OVERSAMPLING = 6


def pipes_function(X: np.ndarray, c: float) -> np.ndarray:
    """F(x) = g² + z² - c at the rows of X (unit coordinates)."""
    x, y, z = X[:, 0], X[:, 1], X[:, 2]
    r2 = x * x + y * y
    g = r2 * r2 - x * x + y * y
    return g * g + z * z - c


def pipes_gradient(X: np.ndarray) -> np.ndarray:
    """∇F = (2g (4x r² - 2x), 2g (4y r² + 2y), 2z) at the rows of X."""
    x, y, z = X[:, 0], X[:, 1], X[:, 2]
    r2 = x * x + y * y
    g = r2 * r2 - x * x + y * y
    return np.column_stack([2 * g * (4 * x * r2 - 2 * x), 2 * g * (4 * y * r2 + 2 * y), 2 * z])


def pipes_bounds(c: float) -> np.ndarray:
    """An axis-aligned box (2, 3) containing F ≤ 0 (rows: low corner, high corner).

    On F ≤ 0, |g| ≤ √c and |z| ≤ √c. From g ≥ r⁴ - r²: r² ≤ (1 + sqrt(1 + 4√c))/2 =: ρ²,
    so |x|, |y| ≤ ρ; from g ≥ x⁴ - x² + y² ≥ y² - 1/4: y² ≤ √c + 1/4.
    """
    sc = np.sqrt(c)
    rho = np.sqrt(0.5 * (1.0 + np.sqrt(1.0 + 4.0 * sc)))
    ymax = min(rho, np.sqrt(sc + 0.25))
    hi = np.array([rho, ymax, sc])
    return np.vstack([-hi, hi])


def project_to_surface(X: np.ndarray, c: float, tol: float = 1e-14, max_iter: int = 50):
    """Newton steps along the gradient, x ← x - F ∇F / |∇F|², until |F| ≤ tol."""
    X = X.copy()
    for _ in range(max_iter):
        F = pipes_function(X, c)
        if np.max(np.abs(F), initial=0.0) <= tol:
            break
        G = pipes_gradient(X)
        X -= (F / np.einsum("ij,ij->i", G, G))[:, None] * G
    return X


def thin_shell_candidates(draw, n: int, c: float, half_width: float):
    """Keep box samples from ``draw(m)`` within |F|/|∇F| < half_width of the surface.

    Uniform samples in a symmetric shell project to a density uniform w.r.t. area up to
    O(half_width²·curvature²) (the linear term 2H·distance of the volume element cancels).
    """
    out, have = [], 0
    while have < n:
        C = draw(max(4096, 30 * (n - have)))
        G = pipes_gradient(C)
        dist = np.abs(pipes_function(C, c)) / np.sqrt(np.einsum("ij,ij->i", G, G))
        keep = C[dist < half_width]
        out.append(keep)
        have += keep.shape[0]
    return np.concatenate(out)[:n]


class ConnectedPipes(SurfaceSource):
    """Closed genus-2 tube surface F = g(x,y)² + z² - c = 0, coordinates times ``scale``.

    random: uniform in a thin shell around the surface, then projected onto F = 0 by Newton
    steps along ∇F: independent points, uniform w.r.t. area to O(δ²) (δ: shell half-width,
    a tenth of the thinnest tube half-thickness √c/2).
    structured: a deterministic Halton sequence in the same shell, projected, then
    OVERSAMPLING× thinned by greedy farthest-point selection (quasi-uniform, Poisson-disk
    like). Both give exactly n_points points with |F| ≤ 1e-14 (unit coordinates).
    Exact: χ = -2, genus 2. The area has no closed form (not given).
    """

    @dataclass
    class Config:
        n_points: int = 2000
        sampling: str = "structured"
        c: float = 0.02
        scale: float = 1.0
        n_markers: Optional[int] = None

    description: ClassVar[str] = "Closed genus-2 tube around a figure-eight (connected pipes)."
    parameter_constraints: ClassVar[dict[str, str]] = {
        **COMMON_CONSTRAINTS,
        "c": "number in (0, 1/16): squared tube half-thickness (genus 2 needs c < 1/16)",
        "scale": "finite number > 0: length unit (lateral extent ≈ 2.1·scale)"}
    name: ClassVar[str] = "connected_pipes"

    def __init__(self, *, n_points: int = 2000, sampling: str = "structured",
                 c: float = 0.02, scale: float = 1.0, n_markers: Optional[int] = None):
        self.n_points = n_points
        self.sampling = sampling
        self.c = c
        self.scale = scale
        self.n_markers = n_markers

    def _check(self) -> None:
        ok = isinstance(self.c, (int, float)) and not isinstance(self.c, bool)
        require(ok and 0.0 < self.c < 1.0 / 16.0, "c", self.c,
                "must be in (0, 1/16) (at 1/16 the lobes' holes close and genus drops)",
                "Use e.g. c=0.02 (tube half-thickness √c ≈ 0.14).")
        require_positive("scale", self.scale)

    def implicit_function(self, X: np.ndarray) -> np.ndarray:
        """F at points given in output (scaled) coordinates."""
        return pipes_function(np.asarray(X, dtype=np.float64) / float(self.scale), float(self.c))

    def _sample(self, n, sampling, rng):
        c = float(self.c)
        half_width = 0.05 * np.sqrt(c)
        lo, hi = pipes_bounds(c)
        # the shell reaches half_width outside F ≤ 0: widen the box or lose its outer half
        lo, hi = lo - 3 * half_width, hi + 3 * half_width
        if sampling == "random":
            C = thin_shell_candidates(lambda m: rng.uniform(lo, hi, (m, 3)), n, c, half_width)
            X = project_to_surface(C, c)
        else:
            from scipy.stats import qmc

            from .farthest_point import farthest_point_order

            halton = qmc.Halton(d=3, scramble=False)
            halton.fast_forward(1)  # skip the corner (0, 0, 0)
            C = thin_shell_candidates(lambda m: lo + (hi - lo) * halton.random(m),
                                      OVERSAMPLING * n, c, half_width)
            X = project_to_surface(C, c)
            X = X[farthest_point_order(X, n, 0)]
        return float(self.scale) * X, None

    def _exact(self):
        return {"euler_characteristic": -2, "genus": 2, "total_gaussian_curvature": -4.0 * np.pi}
