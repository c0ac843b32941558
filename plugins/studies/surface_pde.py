"""A scalar PDE on a point-set surface against its exact solution, under refinement.

The study asks the physics (``physics.solve``, then ``field_at_quadrature``: the protocol,
no physics module imported) for the field u_h and its surface gradient at the quadrature
points, and measures the relative errors against the exact ``exact`` (an expression of
x, y, z, r, θ, φ on the surface)

    e_L2 = ‖u_h − u‖ / ‖u‖,   e_H1 = ‖∇_Γ(u_h − u)‖ / ‖∇_Γ u‖   (∫ over the atlas, Eq. 14),

with ∇_Γ u = (I − n nᵀ) ∇ũ for any smooth extension ũ of the expression off the surface
(central differences, step 1e-6 × size). With ``refinement`` (source.n_points values) it
repeats the solve at each resolution and reports the observed rates
log(e_i/e_{i+1}) / log(h_i/h_{i+1}), h ∝ N^(−1/2).
"""
from __future__ import annotations

from dataclasses import dataclass, field as dc_field
from typing import ClassVar, List, Optional

import numpy as np

from pointatlas.constraints import Each, Interval, Types
from pointatlas.stores_config import stores_config

#: markers per patch unless atlas.markers_per_patch says otherwise (the geometry default)
PDE_MARKERS_PER_PATCH = 150


@dataclass
class SurfacePDESettings:
    exact: Optional[str] = None
    field: str = "u"
    refinement: List[int] = dc_field(default_factory=list)
    parameter_constraints: ClassVar[dict] = {
        "exact": [Types(str), None], "field": [Types(str)],
        "refinement": [Each(Interval(int, 10, None))]}


def tangential_gradient(expression: str, x: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(m, 3) (I − n nᵀ) ∇ũ of an expression at points x (central differences)."""
    from pointatlas_kit.expression import evaluate_values

    h = 1e-6 * max(float(np.ptp(x, axis=0).max()), 1e-300)
    g = np.empty_like(x)
    for i in range(3):
        e = np.zeros(3)
        e[i] = h
        g[:, i] = (evaluate_values(expression, x + e) - evaluate_values(expression, x - e)) / (2 * h)
    return g - (g * normals).sum(axis=1)[:, None] * normals


def errors(data: dict, exact: str) -> tuple[float, float]:
    """(relative L2 error, relative H1-seminorm error) of a scalar field's quadrature data."""
    from pointatlas_kit.expression import evaluate_values

    w, x = data["weights"], data["positions"]
    u = evaluate_values(exact, x)
    gu = tangential_gradient(exact, x, data["normals"])
    du = data["values"][:, 0] - u
    dg = data["gradients"][:, 0] - gu
    l2 = np.sqrt(w @ du ** 2) / np.sqrt(w @ u ** 2)
    h1 = np.sqrt(w @ (dg ** 2).sum(axis=1)) / np.sqrt(w @ (gu ** 2).sum(axis=1))
    return float(l2), float(h1)


@stores_config
class SurfacePDE:
    """Solve the physics on the source's surface; errors against ``exact`` and their rates."""

    Config = SurfacePDESettings
    description: ClassVar[str] = ("A scalar surface PDE (e.g. physics=laplace_beltrami) against "
                                  "its exact solution: relative L2 and H1 errors and rates.")

    def check_config(self) -> None:
        """The exact solution parses (the numbers are checked by the declared constraints)."""
        if self.exact is not None:
            from pointatlas_kit.expression import parse_expression

            parse_expression(self.exact)

    def _solve(self, ctx, n_points=None):
        from pointatlas_atlas.plugin import study_atlas_settings

        a = study_atlas_settings(ctx, self, markers_per_patch=PDE_MARKERS_PER_PATCH)
        a.check()
        source = ctx.plugin("source", **({} if n_points is None else {"n_points": n_points}))
        cloud = source.load(ctx.rng("source"))
        physics = ctx.plugin("physics")
        ds = physics.solve(ctx, cloud=cloud, atlas_settings=a)
        return ds, physics, cloud

    def run(self, ctx):
        from pointatlas.errors import ConfigError

        with ctx.timed("solve"):
            ds, physics, cloud = self._solve(ctx)
        if not callable(getattr(physics, "field_at_quadrature", None)):
            raise ConfigError(f"study=surface_pde needs a physics with field_at_quadrature "
                              f"(the kit's scalar PDEs); physics={ctx.choices.get('physics')}.")
        ds.attrs["title"] = f"{ctx.choices.get('physics')} on {cloud.name}"
        if self.exact is None:
            return ds
        l2, h1 = errors(physics.field_at_quadrature(self.field), self.exact)
        ctx.log.info("N = %d: relative L2 error %.3e, H1 error %.3e", cloud.n_points, l2, h1)
        ds["l2_error"] = ((), l2, {"long_name": "relative L2 error of u", "units": "1"})
        ds["h1_error"] = ((), h1, {"long_name": "relative H1-seminorm error of u",
                                   "units": "1"})
        if self.refinement:
            rows = []
            own = getattr(ctx.plugin("source"), "n_points", None)
            for n in self.refinement:
                if n == own == cloud.n_points:  # the run's own cloud (same seed): solved above
                    rows.append((n, int(ds["n_dof"]), l2, h1))
                else:
                    with ctx.timed(f"solve_{n}"):
                        d, p, c = self._solve(ctx, n)
                    rows.append((c.n_points, int(d["n_dof"]),
                                 *errors(p.field_at_quadrature(self.field), self.exact)))
                ctx.log.info("refinement N = %d: L2 %.3e, H1 %.3e", *rows[-1][:1], *rows[-1][2:])
            R = np.array(rows, float)
            ds = ds.assign_coords(refinement=("refinement", np.arange(len(R)), {
                "long_name": "refinement level (index into study.refinement)", "units": "1"}))
            ds["refinement_points"] = (("refinement",), R[:, 0].astype(int),
                                       {"long_name": "points of the cloud", "units": "1"})
            ds["refinement_dof"] = (("refinement",), R[:, 1].astype(int),
                                    {"long_name": "degrees of freedom", "units": "1"})
            for j, key in ((2, "l2"), (3, "h1")):
                ds[f"refinement_{key}_error"] = (("refinement",), R[:, j], {
                    "long_name": f"relative {key.upper()} error", "units": "1"})
                h = R[:, 0] ** -0.5
                rate = np.log(R[:-1, j] / R[1:, j]) / np.log(h[:-1] / h[1:])
                ds[f"refinement_{key}_rate"] = (("refinement",), np.append(np.nan, rate), {
                    "long_name": f"observed {key.upper()} convergence rate in h ∝ N^-1/2",
                    "units": "1"})
        return ds
