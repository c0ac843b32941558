"""Physics plugin ``stokes_axisymmetric``: Stokes flow round bodies of revolution by
boundary elements (single layer for the total traction, double layer for the exterior one).

``solve(ctx, shapes=…, velocities=…, times=None, motion="free")``:

* ``shapes`` (n, 2) or (K+1, n, 2): generating curves as (r, z) nodes, top pole first
  (:mod:`.meridian`); ``velocities`` the same with (v_r, v_z, v_φ) at each node. One shape
  may also be a scipy ``BSpline`` of (r, z) with its velocity a ``BSpline`` of
  (v_r, v_z, v_φ) on the same parameter.
* ``motion="prescribed"``: the velocities are the whole surface motion (a towed or spun
  body); the Dataset gives the axial force and torque on the fluid.
* ``motion="free"``: the velocities are the shape change (and tangential or swirl motion) in
  the body frame; the rigid V_c and ω follow from zero axial force and torque
  (:mod:`.self_propulsion`). With ``times`` the shapes are a stroke (the last repeating the
  first) and the Dataset adds its displacement, rotation, powers and efficiencies
  (:mod:`.stroke`).

Collocation (piecewise-constant tractions at element mid-points) on the spline geometry;
units as given (viscosity μ × velocity / length for tractions).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from pointatlas.constraints import Interval, Options
from pointatlas.stores_config import stores_config


@dataclass
class StokesAxisymmetricConfig:
    """μ (> 0); elements per shape and their spacing in the chord-length parameter
    (``cosine`` refines towards the poles); Gauss points per element and on each half of
    the singular one; ``permeation``: ``uniform`` adds −V̇/S along the normal of a
    volume-changing shape (the SI's choice), ``none`` refuses such shapes;
    ``periodicity_tol``: how far (× body length) a stroke's last shape may be from its first."""

    viscosity: float = 1.0
    n_elements: int = 64
    element_spacing: str = "uniform"
    gauss_points: int = 8
    singular_points: int = 16
    permeation: str = "uniform"
    periodicity_tol: float = 1.0e-6
    parameter_constraints: ClassVar[dict] = {
        "viscosity": [Interval(float, 0, None, closed="neither")],
        "n_elements": [Interval(int, 4, 4000)],
        "element_spacing": [Options(("uniform", "cosine"))],
        "gauss_points": [Interval(int, 2, 64)],
        "singular_points": [Interval(int, 4, 64)],
        "permeation": [Options(("uniform", "none"))],
        "periodicity_tol": [Interval(float, 0, None, closed="neither")]}


@stores_config
class StokesAxisymmetric:
    """Axisymmetric Stokes boundary elements: drag, torque, swimming by shape change."""

    Config = StokesAxisymmetricConfig
    description: ClassVar[str] = ("Stokes flow round bodies of revolution (axisymmetric "
                                  "boundary elements): drag, torque, self-propulsion, strokes.")

    def _discretisation(self):
        from .stroke import Discretisation

        return Discretisation(self.n_elements, self.gauss_points, self.singular_points,
                              self.element_spacing)

    def _check_volume(self, solved):
        from pointatlas.errors import InputError

        if self.permeation != "none":
            return
        for k, (el, s) in enumerate(solved):
            scale = float(np.abs(s.velocity).max() * el.ring_area.sum()) or 1.0
            if abs(s.volume_rate) > 1e-8 * scale:
                raise InputError(f"shape {k} changes its volume (V̇ = {s.volume_rate:.3g}) but "
                                 f"physics.permeation=none; a single-layer swimmer needs "
                                 f"∫ v·n dS = 0. Set physics.permeation=uniform.")

    def solve(self, ctx, *, shapes, velocities, times=None, motion: str = "free"):
        from pointatlas.constraints import validate_parameters
        from pointatlas.errors import ConfigError

        from .results import shapes_dataset, stroke_dataset
        from .stroke import solve_one, swim_stroke

        validate_parameters(self, prefix="physics")
        if motion not in ("free", "prescribed"):
            raise ConfigError(f"motion={motion!r}: use 'free' (self-propelled) or "
                              f"'prescribed' (towed or spun).")
        from scipy.interpolate import BSpline

        disc, perm = self._discretisation(), self.permeation == "uniform"
        log = getattr(ctx, "log", None)
        if isinstance(shapes, BSpline):          # one shape given as a B-spline of (r, z)
            X, V = [shapes], [velocities]
        else:
            X, V = np.asarray(shapes, dtype=np.float64), np.asarray(velocities, dtype=np.float64)
        if times is None:
            if getattr(X, "ndim", 3) == 2:
                X, V = X[None], V[None]
            solved = [solve_one(x, v, self.viscosity, disc, motion == "free", perm)
                      for x, v in zip(X, V)]
            self._check_volume(solved)
            ds = shapes_dataset(solved)
        else:
            if motion != "free":
                raise ConfigError("a stroke (times given) is always self-propelled; use "
                                  "motion='free'.")
            sol = swim_stroke(times, X, V, self.viscosity, disc, permeation=perm,
                              tol=self.periodicity_tol, log=log)
            self._check_volume(sol.shapes)
            ds = stroke_dataset(sol, float(np.ptp(sol.mean_shape[:, 1])))
        ds["viscosity"] = ((), float(self.viscosity), {"long_name": "viscosity μ",
                                                       "units": "viscosity"})
        return ds
