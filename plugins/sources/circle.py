"""The circle of radius R in the plane: the simplest closed curve (d = 1, D = 2)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.stores_config import stores_config

from .parametric_curve import ParametricCurve
from .surface_source import COMMON_CONSTRAINTS, POSITIVE


@stores_config
class Circle(ParametricCurve):
    """Circle of radius ``radius`` centred at the origin of R^2, γ(t) = R (cos t, sin t).

    structured: equally spaced; random: uniform in arc length.
    Exact: length 2πR, curvature 1/R, ∫κ² ds = 2π/R, total curvature ∫κ ds = 2π.
    """

    @dataclass
    class Config:
        n_points: int = 200
        sampling: str = "structured"
        radius: float = 1.0
        n_markers: Optional[int] = None

        parameter_constraints: ClassVar[dict[str, list]] = {**COMMON_CONSTRAINTS,
                                                            "radius": POSITIVE}

    description: ClassVar[str] = "Circle of given radius in the plane (a closed curve, d = 1)."
    name: ClassVar[str] = "circle"
    closed: ClassVar[bool] = True

    def _span(self):
        return 0.0, 2.0 * np.pi

    def _derivatives(self, t):
        R, c, s = float(self.radius), np.cos(t), np.sin(t)
        return (R * np.column_stack([c, s]), R * np.column_stack([-s, c]),
                -R * np.column_stack([c, s]))

    def _exact(self):
        R = float(self.radius)
        return {"length": 2.0 * np.pi * R, "radius": R, "curvature": 1.0 / R,
                "total_squared_curvature": 2.0 * np.pi / R, "total_curvature": 2.0 * np.pi,
                "euler_characteristic": 0}
