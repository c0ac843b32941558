"""A fully developed crack band against its exact solution, under refinement.

A straight crack (``study.crack``: its two end points) held at υ = 0 by the physics'
pre-crack selector, with no driving energy (``physics.kinematics=none``): the minimiser of
the AT2 crack energy G_c h ∫ (1 − υ)²/(4κ̄) + κ̄|∇υ|² across it is

    υ(d) = 1 − exp(−d / (2κ̄)),   d = distance to the crack,

and its energy is G_c h L for a crack of length L that crosses the surface (thesis §4, Amiri
et al. 2014, Eq. (8); exact up to tanh(b/2κ̄) for a band of half-width b, 1 − 4e-9 at b = 20κ̄).
With ``physics.crack_model=at1`` (G_c h ∫ 3(1 − υ)/(16κ̄) + (3κ̄/4)|∇υ|², bounded by υ ≤ 1)
the band is compact, υ(d) = 1 − (1 − d/(4κ̄))² for d < 4κ̄ and 1 beyond, with the same
energy G_c h L (Pham et al. 2011).
The study asks the physics (protocol only: ``solve`` and its Dataset) for the crack energy
and the phase field at the points, and reports

    relative_error = E_h / (G_c h L) − 1,   profile_error = max_a |υ_h(x_a) − υ(d_a)|

(the profile's range is 1). With ``refinement`` (source.n_points values) it repeats the
solve and reports both errors and their observed rates in h ∝ N^(−1/2).
"""
from __future__ import annotations

from dataclasses import dataclass, field as dc_field
from typing import ClassVar, List

import numpy as np

from pointatlas.constraints import Each, Interval
from pointatlas.stores_config import stores_config


@dataclass
class CrackBandSettings:
    crack: List[List[float]] = dc_field(default_factory=lambda: [[0.0, -0.5, 0.0],
                                                                 [0.0, 0.5, 0.0]])
    refinement: List[int] = dc_field(default_factory=list)
    parameter_constraints: ClassVar[dict] = {
        "crack": [Each(Each(Interval(float), length=3), length=2)],
        "refinement": [Each(Interval(int, 10, None))]}


def band_profile(d, kappa: float, model: str = "at2"):
    """υ at distance ``d`` (length) from a fully broken straight crack (module doc)."""
    d = np.asarray(d, dtype=np.float64)
    if model == "at1":
        return 1.0 - np.clip(1.0 - d / (4.0 * kappa), 0.0, None) ** 2
    return 1.0 - np.exp(-d / (2.0 * kappa))


def band_errors(ds, positions, crack) -> dict:
    """{crack_energy, crack_energy_reference, relative_error, profile_error} of a solve."""
    from pointatlas_kit.selectors import distance_to_polyline

    V = np.asarray(crack, dtype=np.float64)
    L = float(np.linalg.norm(V[1] - V[0]))
    Gh = float(ds["fracture_toughness"]) * float(ds["thickness"])
    kappa = float(ds["length_scale"])
    E = float(ds["fracture_energy"])
    d = distance_to_polyline(np.asarray(positions), V)
    exact = band_profile(d, kappa, str(ds["crack_model"].values) if "crack_model" in ds
                         else "at2")
    return {"crack_energy": E, "crack_energy_reference": Gh * L,
            "relative_error": E / (Gh * L) - 1.0,
            "profile_error": float(np.abs(ds["phase_field"].values - exact).max())}


_ATTRS = {"crack_energy": ("regularised crack energy (at2: G_c h ∫ (1−υ)²/(4κ̄) + κ̄|∇υ|²)",
                           "energy"),
          "crack_energy_reference": ("G_c h L of the straight crack", "energy"),
          "relative_error": ("crack energy / (G_c h L) − 1", "1"),
          "profile_error": ("max |υ_h − υ(d)| at the points (at2: υ = 1 − exp(−d/2κ̄))",
                            "1")}


@stores_config
class CrackBand:
    """The phase field of a straight crack against 1 − exp(−d/2κ̄) and G_c h L."""

    Config = CrackBandSettings
    description: ClassVar[str] = ("A straight pre-crack's phase field (physics="
                                  "kirchhoff_love_fracture, kinematics=none) against the exact "
                                  "band 1 − exp(−d/2κ̄) and its energy G_c h L, under refinement.")

    def _solve(self, ctx, n_points=None):
        from pointatlas_atlas.plugin import study_atlas_settings

        a = study_atlas_settings(ctx, self)
        a.check()
        source = ctx.plugin("source", **({} if n_points is None else {"n_points": n_points}))
        cloud = source.load(ctx.rng("source"))
        ds = ctx.plugin("physics").solve(ctx, cloud=cloud, atlas_settings=a)
        return ds, cloud

    def run(self, ctx):
        from pointatlas.errors import ConfigError

        with ctx.timed("solve"):
            ds, cloud = self._solve(ctx)
        for key in ("fracture_energy", "phase_field", "length_scale"):
            if key not in ds:
                raise ConfigError(f"study=crack_band needs a phase-field physics (physics="
                                  f"kirchhoff_love_fracture); physics={ctx.choices.get('physics')}"
                                  f" gives no {key!r}.")
        ds.attrs["title"] = f"crack band on {cloud.name}"
        e = band_errors(ds, cloud.points, self.crack)
        for k, v in e.items():
            ds[k] = ((), v, {"long_name": _ATTRS[k][0], "units": _ATTRS[k][1]})
        ctx.log.info("N = %d: crack energy %.6g against %.6g (%+.3e), profile error %.3e",
                     cloud.n_points, e["crack_energy"], e["crack_energy_reference"],
                     e["relative_error"], e["profile_error"])
        if self.refinement:
            rows = []
            for n in self.refinement:
                with ctx.timed(f"solve_{n}"):
                    d, c = self._solve(ctx, n)
                r = band_errors(d, c.points, self.crack)
                rows.append((c.n_points, abs(r["relative_error"]), r["profile_error"]))
                ctx.log.info("refinement N = %d: |energy error| %.3e, profile error %.3e",
                             *rows[-1])
            R = np.array(rows, float)
            ds = ds.assign_coords(refinement=("refinement", np.arange(len(R)), {
                "long_name": "refinement level", "units": "1"}))
            ds["refinement_points"] = (("refinement",), R[:, 0].astype(int),
                                       {"long_name": "points of the cloud", "units": "1"})
            h = R[:, 0] ** -0.5
            for j, key in ((1, "energy"), (2, "profile")):
                ds[f"refinement_{key}_error"] = (("refinement",), R[:, j], {
                    "long_name": f"{key} error (absolute relative energy error; max profile "
                                 "error)" if key == "energy" else "max profile error",
                    "units": "1"})
                with np.errstate(divide="ignore", invalid="ignore"):
                    rate = np.log(R[:-1, j] / R[1:, j]) / np.log(h[:-1] / h[1:])
                ds[f"refinement_{key}_rate"] = (("refinement",), np.append(np.nan, rate), {
                    "long_name": f"observed {key} error rate in h ∝ N^-1/2", "units": "1"})
        return ds
