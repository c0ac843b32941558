"""Square plate of the pinched-plate benchmark (thesis L1337, Paper 1 §4.2, Fig. 7–8).

Side L = 10 in the plane z = 0, centred at the origin; the quarter model (thesis Fig. 7b,
dashed) keeps x, y ∈ [0, L/2] with symmetry edges x = 0 and y = 0.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.stores_config import stores_config

from .shell_source import SHELL_CONSTRAINTS, ShellSource, intervals, jitter, rectangle_grid
from .surface_source import POSITIVE


@stores_config
class SquarePlate(ShellSource):
    """Square plate of side ``length`` in z = 0 (full: [−L/2, L/2]², quarter: [0, L/2]²).

    structured: (m+1)×(m+1) grid, m = round(side/h), h = sqrt(area/n_points), so the count
    is close to n_points (full: m even, so the centre is a grid point); grid lines on all four edges. random: that grid
    jittered (edge points slide along their edge, corners fixed).
    Parameters: (x, y). Exact: area, χ = 1 (a disc), genus 0, one boundary curve.
    """

    @dataclass
    class Config:
        n_points: int = 441
        sampling: str = "structured"
        length: float = 10.0
        model: str = "full"
        n_markers: Optional[int] = None

        # length: side of the full plate; model 'full' ([-L/2, L/2]^2) or 'quarter' ([0, L/2]^2)
        parameter_constraints: ClassVar[dict[str, list]] = {**SHELL_CONSTRAINTS,
                                                            "length": POSITIVE}

    description: ClassVar[str] = "Square plate of the pinched-plate benchmark (full or quarter)."
    name: ClassVar[str] = "square_plate"


    def _side_range(self):
        L = float(self.length)
        return (0.0, L / 2) if self.model == "quarter" else (-L / 2, L / 2)

    def _area(self) -> float:
        a, b = self._side_range()
        return (b - a) ** 2

    def _grid(self, h, rng):
        a, b = self._side_range()
        m = intervals(b - a, h, multiple=1 if self.model == "quarter" else 2)
        x, y, ex, ey = rectangle_grid((a, b), m, (a, b), m)
        if rng is not None:
            step = (b - a) / m
            x = jitter(x, step, ex, rng, a, b)
            y = jitter(y, step, ey, rng, a, b)
        return np.column_stack([x, y, np.zeros_like(x)]), np.column_stack([x, y])

    def _exact(self):
        return {"area": self._area(), "length": float(self.length), "euler_characteristic": 1,
                "genus": 0, "n_boundary_curves": 1}
