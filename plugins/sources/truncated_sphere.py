"""The truncated sphere of thesis Fig. 5 and its quarter (Table 1, thesis L150-165, L2085).

What the thesis says (line numbers of millan-2012-thesis.txt):

* L151, L1895: "a set of scattered points quasi-uniformly distributed on a truncated sphere";
  L1897: "uniformly sampled points lying on a sphere, describing a large portion of the full
  sphere", with the topology of a disc. The cut is not stated in words.
* L165, L2083-2085: Table 1 is "for the quarter of a truncated sphere", the partition of that
  point set shown in Fig. 6A / Fig. 4A (METIS, L1897). Recursive bisection of a sphere zone
  reaching the pole cuts along meridians (shorter cuts than parallels), so the four parts are
  90° azimuthal wedges from the pole to the cut: our quarter x >= 0, y >= 0.
* The cut: the axis ticks of Fig. 4A that survive in the extracted text (L1905-1925,
  X3 ticks "5 0 5 10" - minus signs are lost - next to "10 ... 10" for X1, X2) show a sphere
  of radius ~10 spanning z in [-5, 10]: the cap beyond |z| = R/2 removed, i.e. cut = 0.5
  (a cap of polar angle 60°).
  The scale-free numbers of Table 1 agree better with cut = 0.5 than with a hemisphere
  (cut = 0): PCA raw/AIC 1.58 vs 1.70 (thesis 1.53), E_S after AIC relative to PCA's for LLE
  2.22 vs 2.53 (thesis 2.14) and MLLE 0.143 vs 0.157 (thesis 0.138) (N = 1000, k = 12).
* Number of points, radius: not given (see experiments/table1_aic.yaml).
* Sampling: "quasi-uniform" -> ``structured`` (random sampling makes Isomap's graph
  geodesics zig-zag: its AIC stress is then 1.1x PCA's instead of the thesis' 0.26x).

We use the sphere of radius R with the polar cap z > cut·R removed (default cut = 0.5), and
for the quarter additionally x >= 0, y >= 0 (the removed cap is on top instead of the bottom
of Fig. 4A: the same set up to a reflection).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.constraints import Interval

from .lattices import allocate_counts, fibonacci_band, staggered_rows
from .sphere import sphere_parameters, spherical_to_cartesian
from .surface_source import COMMON_CONSTRAINTS, POSITIVE, SurfaceSource


def spherical_rows(n: int, cut: float, phi_span: float):
    """Structured lattice on the zone z ≤ cut (unit sphere), azimuth in [0, phi_span].

    Rows are equally spaced in polar angle (constant meridian spacing h); row j gets a
    number of points proportional to its length sinθ_j·phi_span (largest remainder, total
    exactly n), equally spaced at cell centres so the two meridian edges are half a spacing
    away. Returns ``(z, phi)``.
    """
    theta_cut = np.arccos(cut)
    area = (1.0 + cut) * phi_span
    h = np.sqrt(area / n)
    n_rows = max(1, int(round((np.pi - theta_cut) / h)))
    theta_rows = theta_cut + (np.arange(n_rows) + 0.5) * (np.pi - theta_cut) / n_rows
    counts = allocate_counts(n, np.sin(theta_rows))
    row, phi = staggered_rows(counts, phi_span, periodic=False)
    return np.cos(theta_rows[row]), phi


class TruncatedSphere(SurfaceSource):
    """Sphere of radius ``radius`` without the polar cap z > cut·radius (a disc topologically).

    structured: Fibonacci lattice restricted to the zone (equal-area, quasi-uniform).
    random: uniform w.r.t. area (z uniform in [-R, cut·R] by Archimedes, φ uniform).
    Exact: area 2πR²(1 + cut), χ = 1, genus 0, one boundary circle of radius R·sqrt(1-cut²).
    """

    @dataclass
    class Config:
        n_points: int = 1000
        sampling: str = "structured"
        radius: float = 1.0
        cut: float = 0.5
        n_markers: Optional[int] = None

        # cut: the cap z > cut·radius is removed
        parameter_constraints: ClassVar[dict[str, list]] = {
            **COMMON_CONSTRAINTS, "radius": POSITIVE,
            "cut": [Interval(float, -1, 1, closed="neither")]}

    description: ClassVar[str] = "Sphere with the polar cap z > cut·R removed (thesis Fig. 5)."
    name: ClassVar[str] = "truncated_sphere"
    phi_span: ClassVar[float] = 2.0 * np.pi

    def __init__(self, *, n_points: int = 1000, sampling: str = "structured",
                 radius: float = 1.0, cut: float = 0.5, n_markers: Optional[int] = None):
        self.n_points = n_points
        self.sampling = sampling
        self.radius = radius
        self.cut = cut
        self.n_markers = n_markers

    def _structured(self, n):
        return fibonacci_band(n, -1.0, float(self.cut), self.phi_span)

    def _sample(self, n, sampling, rng):
        if sampling == "structured":
            z, phi = self._structured(n)
        else:
            z = rng.uniform(-1.0, float(self.cut), n)
            phi = rng.uniform(0.0, self.phi_span, n)
        return spherical_to_cartesian(self.radius, z, phi), sphere_parameters(z, phi)

    def _exact(self):
        R, c = float(self.radius), float(self.cut)
        return {
            "area": self.phi_span * R**2 * (1.0 + c),
            "radius": R,
            "cut_height": c * R,
            "euler_characteristic": 1,
            "genus": 0,
            "total_gaussian_curvature": self.phi_span * (1.0 + c),
        }


class QuarterTruncatedSphere(TruncatedSphere):
    """The x ≥ 0, y ≥ 0 quarter of the truncated sphere (thesis Table 1, Fig. 6).

    structured: rows equally spaced in polar angle with counts proportional to their
    length (quasi-uniform, exactly n_points). random: uniform w.r.t. area.
    Exact: area πR²(1 + cut)/2, χ = 1 (a disc), genus 0.
    """

    # Config, __init__ and checks: inherited from TruncatedSphere (same parameters)

    description: ClassVar[str] = "Quarter (x, y ≥ 0) of the truncated sphere (thesis Table 1)."
    name: ClassVar[str] = "quarter_truncated_sphere"
    phi_span: ClassVar[float] = 0.5 * np.pi

    def _structured(self, n):
        return spherical_rows(n, float(self.cut), self.phi_span)
