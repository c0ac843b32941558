"""Numerical parameters of an atlas (thesis Table I, BENCHMARKS.md), with their checks.

Kept free of numpy/scipy imports: it is also the ``Config`` of the surface_geometry study,
imported at start-up to register configs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

from pointatlas.errors import ConfigError


@dataclass
class AtlasSettings:
    """Numerical parameters of the atlas (thesis Table I / BENCHMARKS.md)."""

    n_patches: Optional[int] = None       # None: from markers_per_patch
    markers_per_patch: int = 150
    gamma_lme: float = 0.8
    tol_lme: float = 1e-10
    gamma_pu: float = 4.0
    tol_pu: float = 1e-6
    quadrature_order: int = 6
    least_squares_fit: bool = True
    least_squares_scope: str = "chart"    # 'chart': each chart interpolates its control
    #                                       points; 'global': one set of control points for
    #                                       all charts, the blend fits the points (Paper 2
    #                                       App. B; surface_fit.py)
    chart_margin: float = 3.0             # extra control points within margin·h of supp ψ_κ
    graph_neighbors: int = 10
    max_stress: float = 0.02              # accept a patch's embedding below this stress ...
    max_distortion: float = 2.5           # ... and this 95th-percentile singular-value ratio
    #                                       of the triangles, with no folds
    max_refinement_depth: int = 6

    @classmethod
    def of(cls, obj) -> "AtlasSettings":
        """The atlas settings held as attributes of ``obj`` (a study whose Config extends or
        equals this class)."""
        return cls(**{k: getattr(obj, k) for k in cls.__dataclass_fields__})

    def check(self) -> None:
        for name in ("gamma_lme", "tol_lme", "gamma_pu", "tol_pu", "chart_margin",
                     "max_stress", "max_distortion"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ConfigError(f"{name} = {v!r} is invalid; it must be a finite number > 0.")
        if self.n_patches is not None and self.n_patches < 1:
            raise ConfigError(f"n_patches = {self.n_patches!r} is invalid; use None or >= 1.")
        if self.least_squares_scope not in ("chart", "global"):
            raise ConfigError(f"least_squares_scope = {self.least_squares_scope!r} is invalid; "
                              "use 'chart' (per-chart interpolation) or 'global' (Paper 2 "
                              "App. B: one least-squares fit of the blended atlas).")
        if self.markers_per_patch < 8:
            raise ConfigError(f"markers_per_patch = {self.markers_per_patch!r} is invalid; "
                              "it must be >= 8 (a patch needs enough markers to be embedded).")
