"""Pinched cylinder of the shell obstacle course (thesis L1330–1450, Paper 1 §4).

Open circular cylinder of radius R = 300 and length L = 600, axis z, z ∈ [−L/2, L/2], ends
on rigid diaphragms, pinched by two opposite radial loads at mid-length. Models:
- full: the whole cylinder (two boundary circles);
- quarter: x ≥ 0, y ≥ 0 over the whole length (symmetry edges on the planes x = 0, y = 0,
  diaphragm ends z = ±L/2); loads along ±x sit on its edge y = 0;
- eighth: x ≥ 0, y ≥ 0, z ≥ 0 (additionally the symmetry edge z = 0), the classical model.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.stores_config import stores_config

from .shell_source import SHELL_CONSTRAINTS, ShellSource, intervals, jitter, rectangle_grid
from pointatlas.constraints import Options

from .surface_source import POSITIVE


@stores_config
class Cylinder(ShellSource):
    """Cylinder (R cosφ, R sinφ, z): full φ ∈ [0, 2π), quarter/eighth φ ∈ [0, π/2].

    structured: grid uniform in arc length Rφ and in z with spacing ≈ h = sqrt(area/n_points)
    (count rounded to whole rows; periodic in φ for the full model, with a multiple of 4
    points per circle; z = 0 is a grid line), so the load points (±R, 0, 0) are grid points;
    grid lines on all edges.
    random: that grid jittered. Parameters: (φ [rad], z).
    Exact: area 2πRL (quarter /4, eighth /8); χ = 0 (full, an annulus) or 1 (a disc).
    """

    @dataclass
    class Config:
        n_points: int = 800
        sampling: str = "structured"
        radius: float = 300.0
        length: float = 600.0
        model: str = "full"
        n_markers: Optional[int] = None

        # model 'quarter': x, y >= 0; 'eighth': x, y, z >= 0
        parameter_constraints: ClassVar[dict[str, list]] = {
            **SHELL_CONSTRAINTS, "radius": POSITIVE, "length": POSITIVE,
            "model": [Options(("full", "quarter", "eighth"))]}

    description: ClassVar[str] = "Open cylinder of the pinched-cylinder benchmark (full/quarter/eighth)."
    name: ClassVar[str] = "cylinder"


    def _ranges(self):
        L = float(self.length)
        if self.model == "full":
            return (0.0, 2 * np.pi), (-L / 2, L / 2)
        if self.model == "quarter":
            return (0.0, np.pi / 2), (-L / 2, L / 2)
        return (0.0, np.pi / 2), (0.0, L / 2)

    def _area(self) -> float:
        (p0, p1), (z0, z1) = self._ranges()
        return float(self.radius) * (p1 - p0) * (z1 - z0)

    def _grid(self, h, rng):
        R = float(self.radius)
        (p0, p1), (z0, z1) = self._ranges()
        periodic = self.model == "full"
        npp = intervals(R * (p1 - p0), h, multiple=4 if periodic else 1)
        nz = intervals(z1 - z0, h, multiple=1 if self.model == "eighth" else 2)
        phi, z, ep, ez = rectangle_grid((p0, p1), npp, (z0, z1), nz, periodic_u=periodic)
        if rng is not None:
            phi = jitter(phi, (p1 - p0) / npp, ep, rng, None if periodic else p0,
                         None if periodic else p1)
            z = jitter(z, (z1 - z0) / nz, ez, rng, z0, z1)
            phi = np.mod(phi, 2 * np.pi) if periodic else phi
        pts = np.column_stack([R * np.cos(phi), R * np.sin(phi), z])
        return pts, np.column_stack([phi, z])

    def _exact(self):
        full = self.model == "full"
        return {"area": self._area(), "radius": float(self.radius), "length": float(self.length),
                "euler_characteristic": 0 if full else 1, "genus": 0,
                "n_boundary_curves": 2 if full else 1}
