"""Numerical parameters of an atlas (thesis Table I, BENCHMARKS.md), with their checks.

Kept free of numpy/scipy imports: it is also the ``Config`` of the surface_geometry study,
imported at start-up to register configs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import List, Optional

from pointatlas.errors import ConfigError


#: markers per patch of a geometry study's atlas (and of an Atlas given None)
GEOMETRY_MARKERS_PER_PATCH = 150


@dataclass
class AtlasSettings:
    """Numerical parameters of the atlas (thesis Table I / BENCHMARKS.md)."""

    n_patches: Optional[int] = None       # None: from markers_per_patch
    markers_per_patch: Optional[int] = None  # None: the study's choice (150 for geometry,
    #                                          100 for shells)
    gamma_lme: float = 0.8
    tol_lme: float = 1e-10
    chart_hessians: str = "exact"         # LME Hessians of the charts: 'exact' or 'consistent'
    #                                       (exact for quadratics on irregular points; README
    #                                       "Known limits")
    chart_reproduction: str = "linear"    # 'linear': charts Σ p_a P_a (thesis); 'quadratic',
    #                                       'cubic', 'quartic': the polynomial least-squares fit
    #                                       of the control points on the LME support
    #                                       (curvatures on irregular points; not for shells;
    #                                       README "Known limits")
    gamma_pu: float = 4.0
    tol_pu: float = 1e-6
    quadrature_order: int = 6
    least_squares_fit: bool = True
    least_squares_scope: str = "chart"    # 'chart': each chart interpolates its control
    #                                       points; 'global': one set of control points for
    #                                       all charts, the blend fits the points (Paper 2
    #                                       App. B; surface_fit.py)
    chart_margin: Optional[float] = None  # extra control points within margin·h of supp ψ_κ;
    #                                       None: margin_for(d), 3 for d <= 2, 5 for d >= 3
    graph_neighbors: int = 10
    max_stress: float = 0.02              # accept a patch's embedding below this stress ...
    max_distortion: float = 2.5           # ... and this 95th-percentile singular-value ratio
    #                                       of the triangles, with no folds
    max_refinement_depth: int = 6
    allow_failed_patches: bool = False    # patches failing the chart test after repair
    #                                       (re-embedding, splitting; chart_repair.py): False
    #                                       refuses the atlas, True keeps them, flagged
    orientation: Optional[List[float]] = None  # the side an open surface's normals face
    #                                       (n·e > 0 on average; orientation.py); None: the
    #                                       first chart's. Closed surfaces: always outward

    @classmethod
    def of(cls, obj) -> "AtlasSettings":
        """The atlas settings held as attributes of ``obj`` (a study whose Config extends or
        equals this class)."""
        return cls(**{k: getattr(obj, k) for k in cls.__dataclass_fields__})

    def check(self) -> None:
        for name in ("gamma_lme", "tol_lme", "gamma_pu", "tol_pu", "chart_margin",
                     "max_stress", "max_distortion"):
            v = getattr(self, name)
            if v is None and name == "chart_margin":
                continue
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ConfigError(f"{name} = {v!r} is invalid; it must be a finite number > 0.")
        if self.chart_hessians not in ("exact", "consistent"):
            raise ConfigError(f"chart_hessians = {self.chart_hessians!r} is invalid; use 'exact' "
                              "(∂²p_a of the LME basis) or 'consistent' (second-order consistent "
                              "Hessians, for curvatures on irregular points).")
        if self.chart_reproduction not in ("linear", "quadratic", "cubic", "quartic"):
            raise ConfigError(f"chart_reproduction = {self.chart_reproduction!r} is invalid; "
                              "use 'linear' (LME charts, the thesis) or 'quadratic', 'cubic', "
                              "'quartic' (the polynomial fit of that degree on the LME support, "
                              "for curvature on irregular points).")
        if self.n_patches is not None and self.n_patches < 1:
            raise ConfigError(f"n_patches = {self.n_patches!r} is invalid; use None or >= 1.")
        if self.least_squares_scope not in ("chart", "global"):
            raise ConfigError(f"least_squares_scope = {self.least_squares_scope!r} is invalid; "
                              "use 'chart' (per-chart interpolation) or 'global' (Paper 2 "
                              "App. B: one least-squares fit of the blended atlas).")
        e = self.orientation
        if e is not None and not (len(e) >= 1 and all(isinstance(v, (int, float))
                                                       and math.isfinite(v) for v in e)
                                  and any(v != 0 for v in e)):
            raise ConfigError(f"orientation = {list(e)!r} is invalid; give a non-zero direction "
                              "[nx, ny, nz], the side the normals of an open surface face "
                              "(e.g. [0, 0, 1]), or leave it unset.")
        if not isinstance(self.allow_failed_patches, bool):
            raise ConfigError(f"allow_failed_patches = {self.allow_failed_patches!r} is invalid; "
                              "use true (keep patches whose charts fail, results flagged) or "
                              "false (refuse such an atlas, the default).")
        if self.markers_per_patch is not None and self.markers_per_patch < 8:
            raise ConfigError(f"markers_per_patch = {self.markers_per_patch!r} is invalid; "
                              "it must be >= 8 (a patch needs enough markers to be embedded).")

    def margin_for(self, d: int) -> float:
        """The chart margin (in units of the median point spacing h) for d-dimensional charts.

        An LME chart flattens towards the convex hull of its control points: its image there
        is the chord between boundary points (Paper 1 §2.3, the ghost-node remark of Paper 2
        §5.1), so supp ψ_κ must stay a few spacings inside the hull. 3h is enough on
        surfaces; the hull of scattered points in d = 3 is more ragged, and on S^3 ⊂ R^4
        (2 000 to 8 000 points) a 3h margin left 4 % of the quadrature weight on chords up
        to 17 % inside the sphere while 5h brought the volume error down with N
        (benchmarks/three_sphere_convergence.py). An explicit ``chart_margin`` wins.
        """
        if self.chart_margin is not None:
            return float(self.chart_margin)
        return 3.0 if int(d) <= 2 else 5.0
