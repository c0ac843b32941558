"""Rectangular strip: a cantilever or tensile specimen, x ∈ [0, L], y ∈ [−b/2, b/2], z = 0.

For the in-plane bending of a cantilever (``fracture_bending``: clamped at x = 0, the end
x = L moved across the strip) and other beam-like plates. The structured grid has the
mid-line y = 0 as a grid line, so the two halves y > 0 and y < 0 are mirror images point for
point.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.stores_config import stores_config

from .shell_source import SHELL_CONSTRAINTS, ShellSource, intervals, jitter, rectangle_grid
from .surface_source import POSITIVE


@stores_config
class RectangularStrip(ShellSource):
    """Strip of ``length`` L (along x, from 0) and ``width`` b (along y, centred) in z = 0.
    structured: grid of spacing ≈ sqrt(area/n_points), an even number of intervals across
    (the mid-line is a grid line); random: that grid jittered, edge points sliding along
    their edge. Parameters (x, y). Exact: area L b, χ = 1, genus 0, one boundary curve."""

    @dataclass
    class Config:
        n_points: int = 1025
        sampling: str = "structured"
        length: float = 1.0
        width: float = 0.25
        model: str = "full"
        n_markers: Optional[int] = None
        parameter_constraints: ClassVar[dict[str, list]] = {
            **SHELL_CONSTRAINTS, "length": POSITIVE, "width": POSITIVE}

    description: ClassVar[str] = "Rectangular strip [0, L] × [−b/2, b/2] (a cantilever)."
    name: ClassVar[str] = "rectangular_strip"

    def _check(self) -> None:
        from pointatlas.errors import ConfigError

        if self.model != "full":
            raise ConfigError("source.model: rectangular_strip has the full model only; "
                              "set source.model=full.")

    def _area(self) -> float:
        return float(self.length) * float(self.width)

    def _grid(self, h, rng):
        L, b = float(self.length), float(self.width)
        mx, my = intervals(L, h), intervals(b, h, multiple=2)
        x, y, ex, ey = rectangle_grid((0.0, L), mx, (-b / 2, b / 2), my)
        if rng is not None:
            x = jitter(x, L / mx, ex, rng, 0.0, L)
            y = jitter(y, b / my, ey, rng, -b / 2, b / 2)
        return np.column_stack([x, y, np.zeros_like(x)]), np.column_stack([x, y])

    def _exact(self):
        return {"area": self._area(), "length": float(self.length),
                "euler_characteristic": 1, "genus": 0, "n_boundary_curves": 1}
