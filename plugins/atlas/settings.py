"""Numerical parameters of an atlas (thesis Table I, BENCHMARKS.md), with their checks.

Kept free of numpy/scipy imports: it is also the ``Config`` of the surface_geometry study,
imported at start-up to register configs. Each value's range is declared in
``AtlasSettings.parameter_constraints`` (:mod:`pointatlas.constraints`).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import ClassVar, List, Optional

from pointatlas.constraints import Each, Interval, Options, Types, validate_parameters
from pointatlas.errors import ConfigError

_POSITIVE = [Interval(float, 0, None, closed="neither")]
_FRACTION = [Interval(float, 0, 1, closed="neither")]


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
    least_squares_fit: bool = True        # linear charts interpolate the points (Paper 2
    #                                       App. B); polynomial charts never (Atlas.interpolates)
    least_squares_scope: str = "chart"    # 'chart': each chart interpolates its control
    #                                       points; 'global': one set of control points for
    #                                       all charts, the blend fits the points (Paper 2
    #                                       App. B; surface_fit.py)
    chart_margin: Optional[float] = None  # extra control points within margin·h of supp ψ_κ;
    #                                       None: margin_for(d), 3 for linear charts with
    #                                       d <= 2, else 5
    graph_neighbors: int = 10
    max_stress: float = 0.02              # accept a patch's embedding below this stress ...
    max_distortion: float = 2.5           # ... and this 95th-percentile singular-value ratio
    #                                       of the triangles, with no folds
    max_refinement_depth: int = 6
    allow_failed_patches: bool = False    # patches failing the chart test after repair
    #                                       (re-embedding, splitting; chart_repair.py): False
    #                                       refuses the atlas, True keeps them, flagged
    allow_creases: bool = False           # crease points of the cloud check (a physics):
    #                                       False refuses, True runs on, flagged in warnings
    #                                       (charts departing from their points too)
    orientation: Optional[List[float]] = None  # the side an open surface's normals face
    #                                       (n·e > 0 on average; orientation.py); None: the
    #                                       first chart's. Closed surfaces: always outward

    parameter_constraints: ClassVar[dict[str, list]] = {
        "n_patches": [Interval(int, 1, None), None],
        # a patch needs enough markers to be embedded
        "markers_per_patch": [Interval(int, 8, None), None],
        "gamma_lme": _POSITIVE, "tol_lme": _FRACTION,          # thesis 0.8, 1e-10
        "chart_hessians": [Options(("exact", "consistent"))],
        "chart_reproduction": [Options(("linear", "quadratic", "cubic", "quartic"))],
        "gamma_pu": _POSITIVE, "tol_pu": _FRACTION,            # thesis 4-6, 1e-6
        "quadrature_order": [Interval(int, 1, None)],          # thesis 6
        "least_squares_fit": [Types(bool)],
        "least_squares_scope": [Options(("chart", "global"))],
        "chart_margin": [*_POSITIVE, None],
        "graph_neighbors": [Interval(int, 1, None)],
        "max_stress": _POSITIVE,
        "max_distortion": [Interval(float, 1, None, closed="neither")],  # a singular-value ratio
        "max_refinement_depth": [Interval(int, 0, None)],
        "allow_failed_patches": [Types(bool)], "allow_creases": [Types(bool)],
        "orientation": [Each(Interval(float)), None],          # non-zero: checked in check()
    }

    @classmethod
    def of(cls, obj) -> "AtlasSettings":
        """The atlas settings held as attributes of ``obj`` (a study whose Config extends or
        equals this class)."""
        return cls(**{f.name: getattr(obj, f.name) for f in dataclasses.fields(cls)})

    def check(self) -> None:
        """The declared constraints, and an orientation that is a direction (not zero)."""
        validate_parameters(self)
        e = self.orientation
        if e is not None and not (len(e) >= 1 and any(v != 0 for v in e)):
            raise ConfigError(f"orientation={list(e)!r} is invalid: give a non-zero direction "
                              "[nx, ny, nz], the side the normals of an open surface face "
                              "(e.g. [0, 0, 1]), or leave it unset.")

    def margin_for(self, d: int) -> float:
        """The chart margin (in units of the median point spacing h) for d-dimensional charts.

        An LME chart flattens towards the convex hull of its control points: its image there
        is the chord between boundary points (Paper 1 §2.3, the ghost-node remark of Paper 2
        §5.1), so supp ψ_κ must stay a few spacings inside the hull. 3h is enough on
        surfaces; the hull of scattered points in d = 3 is more ragged, and on S^3 ⊂ R^4
        (2 000 to 8 000 points) a 3h margin left 4 % of the quadrature weight on chords up
        to 17 % inside the sphere while 5h brought the volume error down with N
        (benchmarks/three_sphere_convergence.py). Polynomial charts (``chart_reproduction``
        other than linear) are meant for uneven samples, whose gaps the median spacing h does
        not see: on pyvista's ParametricEllipsoid grid (meridians up to three spacings apart)
        quartic charts with a 3h margin lost 0.57 % (80 × 80) and 0.76 % (100 × 100) of the
        area, with 5h 0.06 % and 0.05 %; they get 5h. An explicit ``chart_margin`` wins.
        """
        if self.chart_margin is not None:
            return float(self.chart_margin)
        return 3.0 if int(d) <= 2 and self.chart_reproduction == "linear" else 5.0
