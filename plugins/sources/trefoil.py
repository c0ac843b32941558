"""The trefoil knot in R^3: a closed curve of varying curvature (d = 1)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.stores_config import stores_config

from .parametric_curve import ParametricCurve
from .surface_source import COMMON_CONSTRAINTS, POSITIVE


@stores_config
class TrefoilKnot(ParametricCurve):
    """Trefoil γ(t) = scale·(sin t + 2 sin 2t, cos t − 2 cos 2t, −sin 3t), t ∈ [0, 2π).

    structured: equally spaced in arc length; random: uniform in arc length. Distinct strands pass
    about 1.2·scale apart or more. Exact: length and ∫κ² ds by the periodic trapezoidal rule on
    8192 parameter samples (converged to round-off; length ≈ 28.826·scale).
    """

    @dataclass
    class Config:
        n_points: int = 400
        sampling: str = "structured"
        scale: float = 1.0
        n_markers: Optional[int] = None

        # scale: length unit of the knot
        parameter_constraints: ClassVar[dict[str, list]] = {**COMMON_CONSTRAINTS,
                                                            "scale": POSITIVE}

    description: ClassVar[str] = "Trefoil knot in R^3 (a closed curve of varying curvature, d = 1)."
    name: ClassVar[str] = "trefoil"
    closed: ClassVar[bool] = True

    def _span(self):
        return 0.0, 2.0 * np.pi

    def _derivatives(self, t):
        a = float(self.scale)
        s1, c1, s2, c2, s3, c3 = (np.sin(t), np.cos(t), np.sin(2 * t), np.cos(2 * t),
                                  np.sin(3 * t), np.cos(3 * t))
        x = np.column_stack([s1 + 2 * s2, c1 - 2 * c2, -s3])
        v = np.column_stack([c1 + 4 * c2, -s1 + 4 * s2, -3 * c3])
        acc = np.column_stack([-s1 - 8 * s2, -c1 + 8 * c2, 9 * s3])
        return a * x, a * v, a * acc
