"""A closed smooth surface of genus 2: a fat tube around a figure-eight ("connected pipes").

Stands in for the "connected pipes" of the thesis (L583, L2557: a shell of complex
topology that admits no single parametric domain). With the Cassini function of the foci
(±1, 0), G(x, y) = ((x−1)² + y²)((x+1)² + y²) (G = 0 at the foci, saddle G = 1 at the
origin) and q = G^{1/4}, the surface (in units of ``scale``) is the level set

    F(x) = (q(x, y) − m)² + (z/ζ)² − w² = 0,

the double of the planar region m − w ≤ q ≤ m + w (a disk with two holes around the foci)
with height z = ±ζ sqrt(w² − (q − m)²). ∇F = (2(q − m)∇q, 2z/ζ²) vanishes on F = 0 only at
critical points of G, so for 0 < m − w < 1 < m + w the surface is smooth, encloses both
foci's holes and is connected through the saddle: genus 2, χ = −2.

Defaults m = 1.2, w = 0.45, ζ = 0.9 were chosen to make the surface "fat" for its area
(area × max principal curvature² ≈ 330, versus several thousand for a thin tube around
the lemniscate), so that a few thousand samples resolve every feature.

Area (no closed form): with u = r², cos 2φ = c, G = u² − 2uc + 1, |∇q|² = u/q² and the
area element of the two graphs z = ±ζ sqrt(w² − (q − m)²) over the plane,

    A = 4 ∫_0^{π/2} dφ ∫ E(u, φ) du,  E = sqrt(w² − s² + ζ² s² |∇q|²) / sqrt(w² − s²),
    s = q − m,

over the u-intervals where |s| ≤ w (end points are roots of quadratics in u). The inner
integrals use u = a + (b − a)(1 − cos t)/2 (removing the 1/sqrt end singularities) and
Gauss–Legendre in t; the outer one Gauss–Legendre split at the angle where the hole
appears (:func:`pipes_area`). For the defaults A = 21.87185879485: adaptive outer quadrature
(scipy quad, epsrel 1e-12) with 100/200/400 inner nodes gives 21.871858794882 /
…853775 / …649448, and the fixed rule of :func:`pipes_area` agrees to < 1e-10 relative; a
marching-cubes mesh of F = 0 with projected vertices converges to it at O(h²).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from .level_set import near_level_set, project_to_level_set
from .surface_source import COMMON_CONSTRAINTS, POSITIVE, SurfaceSource, require

#: Candidates per output point for the structured (farthest-point) selection.
OVERSAMPLING = 6


def _cassini(X: np.ndarray):
    """G and ∇G = (4x(r² − 1), 4y(r² + 1)) at the rows of X."""
    x, y = X[:, 0], X[:, 1]
    r2 = x * x + y * y
    G = r2 * r2 - 2.0 * (x * x - y * y) + 1.0
    return G, 4.0 * x * (r2 - 1.0), 4.0 * y * (r2 + 1.0)


def pipes_function(X: np.ndarray, m: float, w: float, zeta: float) -> np.ndarray:
    """F(x) = (G^{1/4} − m)² + (z/ζ)² − w² at the rows of X (unit coordinates)."""
    G, _, _ = _cassini(X)
    return (G**0.25 - m) ** 2 + (X[:, 2] / zeta) ** 2 - w * w


def pipes_gradient(X: np.ndarray, m: float, w: float, zeta: float) -> np.ndarray:
    """∇F = (2(q − m) ∇q, 2z/ζ²), ∇q = ∇G / (4 G^{3/4})."""
    G, Gx, Gy = _cassini(X)
    G = np.maximum(G, 1e-300)
    f = 2.0 * (G**0.25 - m) / (4.0 * G**0.75)
    return np.column_stack([f * Gx, f * Gy, 2.0 * X[:, 2] / zeta**2])


def pipes_bounds(m: float, w: float, zeta: float) -> np.ndarray:
    """Box (2, 3) containing F ≤ 0: G ≥ (r² − 1)² and q ≤ m + w give r² ≤ 1 + (m + w)²."""
    rho = np.sqrt(1.0 + (m + w) ** 2)
    hi = np.array([rho, rho, zeta * w])
    return np.vstack([-hi, hi])


def project_to_surface(X, m, w, zeta, tol: float = 1e-14, max_iter: int = 60):
    """Newton steps along the gradient, x ← x − F ∇F / |∇F|², until |F| ≤ tol."""
    return project_to_level_set(X, _value_gradient(m, w, zeta), tol, max_iter)


def _value_gradient(m, w, zeta):
    return lambda X: (pipes_function(X, m, w, zeta), pipes_gradient(X, m, w, zeta))


def thin_shell_candidates(draw, n: int, params, half_width: float):
    """Keep box samples from ``draw(k)`` within |F|/|∇F| < half_width of the surface
    (:func:`.level_set.near_level_set`)."""
    return near_level_set(draw, n, _value_gradient(*params), half_width, 4096, 30)


def _graph_area_integral(phi: np.ndarray, m: float, w: float, zeta: float, n_nodes: int):
    """I(φ) = ∫ E(u, φ) du over {u ≥ 0 : |q − m| ≤ w} (module docstring), vectorised in φ."""
    c = np.cos(2.0 * phi)
    lo4, hi4 = (m - w) ** 4, (m + w) ** 4
    u_hi = c + np.sqrt(c * c - 1.0 + hi4)
    s_lo = np.sqrt(np.clip(c * c - 1.0 + lo4, 0.0, None))
    hole = (c > 0) & (c * c - 1.0 + lo4 > 0)
    t, wt = np.polynomial.legendre.leggauss(n_nodes)
    t = 0.5 * np.pi * (t + 1.0)
    wt = 0.5 * np.pi * wt

    def interval(a, b):
        u = a[:, None] + (b - a)[:, None] * 0.5 * (1.0 - np.cos(t))[None, :]
        du = (b - a)[:, None] * 0.5 * np.sin(t)[None, :]
        cc = c[:, None]
        G = u * u - 2.0 * u * cc + 1.0
        q = G**0.25
        s = q - m
        rad = np.clip(w * w - s * s, 1e-300, None)
        E = np.sqrt(rad + zeta**2 * s * s * u / (q * q)) / np.sqrt(rad)
        return (E * du) @ wt

    zero = np.zeros_like(c)
    split = np.where(c > 0, c, zero)  # the minimum of G(u): split there (near-singular peak)
    single = interval(zero, np.minimum(split, u_hi)) + interval(np.minimum(split, u_hi), u_hi)
    u1, u2 = np.where(hole, c - s_lo, 0.0), np.where(hole, c + s_lo, 0.0)
    holed = interval(zero, u1) + interval(u2, u_hi)
    return np.where(hole, holed, single)


def pipes_area(m: float, w: float, zeta: float, n_nodes: int = 200,
               n_angles: int = 200) -> float:
    """Area of F = 0 in unit coordinates by the graph integral of the module docstring.

    Outer integral: Gauss–Legendre on [0, φ*] and [φ*, π/2] (the hole opens at φ*, where
    I(φ) has a square-root kink) after φ = φ* ∓ ℓ s², which makes the kink smooth in s.
    """
    lo4 = (m - w) ** 4
    phi_star = 0.5 * np.arccos(np.sqrt(1.0 - lo4))  # the hole appears for φ < φ*
    s, ws = np.polynomial.legendre.leggauss(n_angles)
    s, ws = 0.5 * (s + 1.0), 0.5 * ws
    total = 0.0
    for length, sign in ((phi_star, -1.0), (0.5 * np.pi - phi_star, 1.0)):
        phi = phi_star + sign * length * s * s
        total += np.sum(_graph_area_integral(phi, m, w, zeta, n_nodes) * 2.0 * length * s * ws)
    return 4.0 * float(total)


class ConnectedPipes(SurfaceSource):
    """Closed genus-2 surface F = (G^{1/4} − m)² + (z/ζ)² − w² = 0, coordinates × ``scale``.

    random: uniform in a thin shell around the surface, then projected onto F = 0 by Newton
    steps along ∇F: independent points, uniform w.r.t. area to O(δ²) (δ: shell half-width).
    structured: a deterministic Halton sequence in the same shell, projected, then
    OVERSAMPLING× thinned by greedy farthest-point selection (quasi-uniform, Poisson-disk
    like). Both give exactly n_points points with |F| ≤ 1e-14 (unit coordinates).
    Exact: χ = −2, genus 2, ∫K dA = −4π; area by :func:`pipes_area` (converged reference).
    """

    @dataclass
    class Config:
        n_points: int = 2000
        sampling: str = "structured"
        core_level: float = 1.2
        half_width: float = 0.45
        height: float = 0.9
        scale: float = 1.0
        n_markers: Optional[int] = None

        # core_level m: level of q = G^{1/4} at the tube's core, with half_width w
        # 0 < m − w < 1 < m + w (genus 2; checked with both); w: half-width of the tube in q;
        # height ζ: the vertical half-thickness of the tube is ζ·w; scale: length unit
        # (lateral extent ≈ 2·sqrt(1+(m+w)²)·scale)
        parameter_constraints: ClassVar[dict[str, list]] = {
            **COMMON_CONSTRAINTS, "core_level": POSITIVE, "half_width": POSITIVE,
            "height": POSITIVE, "scale": POSITIVE}

    description: ClassVar[str] = "Closed genus-2 tube around a figure-eight (connected pipes)."
    name: ClassVar[str] = "connected_pipes"

    def __init__(self, *, n_points: int = 2000, sampling: str = "structured",
                 core_level: float = 1.2, half_width: float = 0.45, height: float = 0.9,
                 scale: float = 1.0, n_markers: Optional[int] = None):
        self.n_points = n_points
        self.sampling = sampling
        self.core_level = core_level
        self.half_width = half_width
        self.height = height
        self.scale = scale
        self.n_markers = n_markers

    def _params(self):
        return float(self.core_level), float(self.half_width), float(self.height)

    def _check(self) -> None:
        m, w, _ = self._params()
        require(0.0 < m - w < 1.0 < m + w, "core_level", self.core_level,
                f"with half_width={w} must satisfy 0 < core_level − half_width < 1 < "
                "core_level + half_width (else the holes close or the tube splits: genus ≠ 2)",
                "Use e.g. core_level=1.2, half_width=0.45.")

    def implicit_function(self, X: np.ndarray) -> np.ndarray:
        """F at points given in output (scaled) coordinates."""
        X = np.asarray(X, dtype=np.float64) / float(self.scale)
        return pipes_function(X, *self._params())

    def _sample(self, n, sampling, rng):
        params = self._params()
        m, w, zeta = params
        half_width = 0.02 * w * min(zeta, 1.0)
        lo, hi = pipes_bounds(*params)
        lo, hi = lo - 3 * half_width, hi + 3 * half_width
        if sampling == "random":
            C = thin_shell_candidates(lambda k: rng.uniform(lo, hi, (k, 3)), n, params,
                                      half_width)
            X = project_to_surface(C, *params)
        else:
            from scipy.stats import qmc

            from .farthest_point import farthest_point_order

            halton = qmc.Halton(d=3, scramble=False)
            halton.fast_forward(1)  # skip the corner (0, 0, 0)
            C = thin_shell_candidates(lambda k: lo + (hi - lo) * halton.random(k),
                                      OVERSAMPLING * n, params, half_width)
            X = project_to_surface(C, *params)
            X = X[farthest_point_order(X, n, 0)]
        return float(self.scale) * X, None

    def _exact(self):
        area = pipes_area(*self._params()) * float(self.scale) ** 2
        return {"euler_characteristic": -2, "genus": 2, "total_gaussian_curvature": -4.0 * np.pi,
                "area": area}
