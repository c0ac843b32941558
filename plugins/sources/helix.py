"""The circular helix in R^3: an open curve of constant curvature and torsion (d = 1)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.stores_config import stores_config

from .parametric_curve import ParametricCurve
from .surface_source import COMMON_CONSTRAINTS, POSITIVE


@stores_config
class Helix(ParametricCurve):
    """Helix γ(t) = (r cos t, r sin t, c t), t ∈ [0, 2π·turns], c = pitch/(2π).

    structured: equally spaced in arc length, both end points included; random: uniform in
    arc length plus the two end points.
    Exact: length 2π·turns·sqrt(r² + c²), curvature κ = r/(r² + c²), torsion c/(r² + c²),
    ∫κ² ds = κ²·length.
    """

    @dataclass
    class Config:
        n_points: int = 200
        sampling: str = "structured"
        radius: float = 1.0
        pitch: float = 1.0
        turns: float = 2.0
        n_markers: Optional[int] = None

        # pitch: rise per turn
        parameter_constraints: ClassVar[dict[str, list]] = {
            **COMMON_CONSTRAINTS, "radius": POSITIVE, "pitch": POSITIVE, "turns": POSITIVE}

    description: ClassVar[str] = "Circular helix in R^3 (an open curve, d = 1)."
    name: ClassVar[str] = "helix"
    closed: ClassVar[bool] = False

    def _span(self):
        return 0.0, 2.0 * np.pi * float(self.turns)

    def _derivatives(self, t):
        r, c = float(self.radius), float(self.pitch) / (2.0 * np.pi)
        cs, sn, one = np.cos(t), np.sin(t), np.ones_like(t)
        return (np.column_stack([r * cs, r * sn, c * t]), np.column_stack([-r * sn, r * cs, c * one]),
                np.column_stack([-r * cs, -r * sn, 0.0 * t]))

    def _exact(self):
        r, c = float(self.radius), float(self.pitch) / (2.0 * np.pi)
        length = float(2.0 * np.pi * float(self.turns) * np.hypot(r, c))
        kappa = r / (r * r + c * c)
        return {"length": length, "curvature": kappa, "torsion": c / (r * r + c * c),
                "total_squared_curvature": kappa**2 * length, "euler_characteristic": 1}
