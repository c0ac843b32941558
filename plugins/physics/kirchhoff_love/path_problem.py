"""What a path-following study asks of a built shell (the physics side of the protocol).

:meth:`KirchhoffLove.path_problem` builds the atlas, the loads F (load factor 1) and the
supports C U = g once and returns a :class:`ShellPath`: the equilibrium problem for the
shared path followers (:mod:`pointatlas_solvers.path_following`), monitors u(p)·e at surface
points, the displacement and energy density at the sampled points, and the facts the study
reports (DOF, sampled points, imposed-displacement supports). A study uses these and no
shell module.
"""
from __future__ import annotations

import numpy as np


class ShellPath:
    """A built, loaded and supported shell ready to follow a load path."""

    def __init__(self, model, settings, F: np.ndarray, constraints):
        from .equilibrium import Equilibrium

        self.model, self.settings = model, settings
        self.problem = Equilibrium(model, settings, F, constraints)
        self.points = model.points
        self.n_dofs = model.dof
        self.n_nodes = model.nodes.shape[0]
        self.n_constraint_rows = constraints.matrix.shape[0]
        self.has_loads = bool(np.any(F))
        from pointatlas_solvers.linear_backends import resolve_backend

        #: the linear-solver backend the path's solves use (``auto`` resolved)
        self.linear_solver = resolve_backend(settings.solver)
        #: (support index, imposed displacement (3,)) of the 'displacement' supports
        self.imposed = [(k, np.asarray(sup.value, float)) for k, sup in
                        enumerate(settings.supports) if sup.kind == "displacement"]

    def probe(self, points, directions):
        """U -> (u(p_i)·e_i)_i at the surface points nearest to ``points`` (k, 3) along unit
        ``directions`` (k, 3): the closest-point projections and the basis there are computed
        once (Paper 2 App. A), then each call is one product."""
        from pointatlas_atlas.evaluation import basis_at
        from pointatlas_atlas.projection import closest_point

        atlas = self.model.atlas
        proj = closest_point(atlas, np.asarray(points, dtype=np.float64).reshape(-1, 3))
        B = basis_at(atlas, proj.chart, proj.xi, order=0).to_csr(self.n_nodes)
        E = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
        return lambda U: np.einsum("ij,ij->i", B @ np.asarray(U).reshape(-1, 3), E)

    def point_fields(self):
        """U -> (u(x_a) (n, 3), energy density (n, 3): membrane, bending, total) at the
        sampled points; the bases are evaluated once, for both (the energy operator's
        quadrature at the points also interpolates u)."""
        from .snapshots import point_energy_operator

        n = self.points.shape[0]
        energy_at = point_energy_operator(self.model)
        B, rows = energy_at.quadrature.interpolation(), energy_at.rows

        def fields(U):
            u = np.full((n, 3), np.nan)
            u[rows] = B @ np.asarray(U).reshape(-1, 3)
            return u, energy_at(U)
        return fields

    def warning(self):
        """The atlas's message about failed patches kept by the user's choice, or None."""
        return self.model.atlas.refinement_warning()


def build_path(physics, ctx, cloud, atlas_settings) -> ShellPath:
    """Atlas, loads and supports of ``physics`` (a KirchhoffLove) on ``cloud``."""
    from .analysis import assemble_loads, assemble_supports, build_model

    s = physics.shell_settings()
    if s.streamed_assembly:
        from pointatlas.errors import ConfigError

        raise ConfigError("physics.streamed_assembly=true is for the linear analysis (one "
                          "assembly); a load path assembles K at every Newton step from the "
                          "kept basis: remove physics.streamed_assembly.")
    model = build_model(cloud, s, atlas_settings, **physics.factories(ctx, atlas_settings),
                        log=ctx.log, linear=False)
    F = assemble_loads(model, s, ctx.log)
    cons = assemble_supports(model, s)
    return ShellPath(model, s, F, cons)
