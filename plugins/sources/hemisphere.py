"""Pinched hemisphere of the shell obstacle course (thesis L1330–1450, Paper 1 §4.4, Fig. 11).

Upper hemisphere z ≥ 0 of radius R = 10, free equator. As in the thesis it is closed at the
pole by default; ``hole_angle_deg = 18`` gives the classical open hemisphere of the
obstacle course and of the nonlinear test (Sze et al. 2004) with a hole of polar angle 18°.
The quarter model keeps x ≥ 0, y ≥ 0 (symmetry edges on the planes x = 0 and y = 0).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.stores_config import stores_config

from .shell_source import JITTER, SHELL_CONSTRAINTS, ShellSource, intervals
from pointatlas.constraints import Interval

from .surface_source import POSITIVE


@stores_config
class Hemisphere(ShellSource):
    """Hemisphere R (sinθ cosφ, sinθ sinφ, cosθ), θ ∈ [hole, 90°]; full or quarter (φ ≤ 90°).

    structured: rings of constant polar angle θ_j equally spaced in arc length (spacing
    h ≈ sqrt(area/n_points)), from the hole edge (or the pole point, closed case) to the
    equator; each ring gets points in proportion to its length (full: a multiple of 4, so the
    load points (±R, 0, 0), (0, ±R, 0) are on the equator; consecutive rings staggered;
    quarter: both end points on the symmetry edges). The count is close to n_points.
    random: that set jittered (θ of interior rings, φ of non-edge points, a random phase per
    full interior ring; pole, hole edge and equator rings keep their θ).
    Parameters: (θ, φ) [rad]. Exact: area 2πR² cos(hole) (quarter /4); χ = 1 (closed or
    quarter) or 0 (full with hole, an annulus).
    """

    @dataclass
    class Config:
        n_points: int = 800
        sampling: str = "structured"
        radius: float = 10.0
        hole_angle_deg: float = 0.0
        model: str = "full"
        n_markers: Optional[int] = None

        # hole_angle_deg: polar angle of the hole at the pole (0: closed, 18: classical open
        # hemisphere); model 'quarter': x >= 0, y >= 0
        parameter_constraints: ClassVar[dict[str, list]] = {
            **SHELL_CONSTRAINTS, "radius": POSITIVE,
            "hole_angle_deg": [Interval(float, 0, 90, closed="left")]}

    description: ClassVar[str] = "Hemisphere of radius 10 (closed, or with a polar hole), full or quarter."
    name: ClassVar[str] = "hemisphere"


    def _span(self) -> float:
        return 2 * np.pi if self.model == "full" else np.pi / 2

    def _area(self) -> float:
        R = float(self.radius)
        return self._span() * R**2 * float(np.cos(np.deg2rad(self.hole_angle_deg)))

    def _grid(self, h, rng):
        R, span, full = float(self.radius), self._span(), self.model == "full"
        t0, t1 = float(np.deg2rad(self.hole_angle_deg)), np.pi / 2
        m = intervals(R * (t1 - t0), h)
        dt = (t1 - t0) / m
        thetas, phis = [], []
        for j in range(m + 1):
            t = t0 + j * dt
            if t == 0.0:  # the pole: one point (distinct points)
                thetas.append(np.zeros(1))
                phis.append(np.zeros(1))
                continue
            edge_ring = j == 0 or j == m
            arc = R * np.sin(t) * span
            if full:
                count = intervals(arc, h, multiple=4)
                k = np.arange(count, dtype=np.float64)
                phi = span * (k + 0.5 * ((m - j) % 2)) / count
                fixed = np.zeros(count, dtype=bool)
                if rng is not None:
                    if j == m:  # keep the four load points of the equator
                        fixed[:: count // 4] = True
                    else:
                        phi = phi + rng.uniform(0.0, span / count)
            else:
                count = intervals(arc, h)
                phi = span * np.arange(count + 1) / count
                fixed = np.zeros(count + 1, dtype=bool)
                fixed[[0, -1]] = True
            theta = np.full(phi.shape, t)
            if rng is not None:
                phi = phi + np.where(fixed, 0.0, rng.uniform(-JITTER, JITTER, phi.shape)
                                     * span / count)
                phi = np.mod(phi, 2 * np.pi) if full else np.clip(phi, 0.0, span)
                if not edge_ring:
                    theta = theta + rng.uniform(-JITTER, JITTER, theta.shape) * dt
            thetas.append(theta)
            phis.append(phi)
        theta, phi = np.concatenate(thetas), np.concatenate(phis)
        s = np.sin(theta)
        pts = R * np.column_stack([s * np.cos(phi), s * np.sin(phi), np.cos(theta)])
        pts[:, 2] = np.where(theta == t1, 0.0, pts[:, 2])  # equator exactly at z = 0
        return pts, np.column_stack([theta, phi])

    def _exact(self):
        open_full = self.model == "full" and self.hole_angle_deg > 0
        return {"area": self._area(), "radius": float(self.radius),
                "hole_angle": float(np.deg2rad(self.hole_angle_deg)),
                "euler_characteristic": 0 if open_full else 1, "genus": 0,
                "n_boundary_curves": 2 if open_full else 1}
