"""Scordelis–Lo roof of the shell obstacle course (thesis L1330–1450, Paper 1 §4.3, Fig. 9).

Cylindrical roof of radius R = 25 and length L = 50 with axis along y, spanning the polar
angle θ ∈ [−40°, 40°] from the vertical: x = R sinθ, z = R cosθ, y ∈ [−L/2, L/2]. The straight
edges θ = ±40° are free, the curved edges y = ±L/2 rest on rigid diaphragms. The quarter model
keeps θ ∈ [0, 40°], y ∈ [0, L/2] (symmetry edges θ = 0 and y = 0).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.stores_config import stores_config

from .shell_source import SHELL_CONSTRAINTS, ShellSource, intervals, jitter, rectangle_grid
from pointatlas.constraints import Interval

from .surface_source import POSITIVE


@stores_config
class ScordelisLoRoof(ShellSource):
    """Cylindrical roof (x, z) = R (sinθ, cosθ), |θ| ≤ half_angle, |y| ≤ L/2.

    structured: grid uniform in arc length Rθ and in y with spacing ≈ h = sqrt(area/n_points)
    (count rounded to whole rows; full: even interval counts, so the mid-side of the free
    edge θ = ±40°, y = 0 is a grid point), grid lines on all edges. random: that grid jittered.
    Parameters: (θ [rad], y). Exact: area 2·R·half_angle·L (quarter: /4), χ = 1, genus 0.
    """

    @dataclass
    class Config:
        n_points: int = 600
        sampling: str = "structured"
        radius: float = 25.0
        length: float = 50.0
        half_angle_deg: float = 40.0
        model: str = "full"
        n_markers: Optional[int] = None

        # model 'quarter': theta >= 0, y >= 0
        parameter_constraints: ClassVar[dict[str, list]] = {
            **SHELL_CONSTRAINTS, "radius": POSITIVE, "length": POSITIVE,
            "half_angle_deg": [Interval(float, 0, 90, closed="right")]}  # half opening angle

    description: ClassVar[str] = "Scordelis-Lo cylindrical roof (R=25, L=50, 40 deg), full or quarter."
    name: ClassVar[str] = "scordelis_lo_roof"


    def _ranges(self):
        T, L = np.deg2rad(float(self.half_angle_deg)), float(self.length)
        if self.model == "quarter":
            return (0.0, T), (0.0, L / 2)
        return (-T, T), (-L / 2, L / 2)

    def _area(self) -> float:
        (t0, t1), (y0, y1) = self._ranges()
        return float(self.radius) * (t1 - t0) * (y1 - y0)

    def _grid(self, h, rng):
        R = float(self.radius)
        (t0, t1), (y0, y1) = self._ranges()
        full = self.model == "full"
        nt = intervals(R * (t1 - t0), h, multiple=2 if full else 1)
        ny = intervals(y1 - y0, h, multiple=2 if full else 1)
        t, y, et, ey = rectangle_grid((t0, t1), nt, (y0, y1), ny)
        if rng is not None:
            t = jitter(t, (t1 - t0) / nt, et, rng, t0, t1)
            y = jitter(y, (y1 - y0) / ny, ey, rng, y0, y1)
        pts = np.column_stack([R * np.sin(t), y, R * np.cos(t)])
        return pts, np.column_stack([t, y])

    def _exact(self):
        return {"area": self._area(), "radius": float(self.radius), "length": float(self.length),
                "half_angle": float(np.deg2rad(self.half_angle_deg)), "euler_characteristic": 1,
                "genus": 0, "n_boundary_curves": 1}
