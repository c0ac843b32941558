"""A linear physics on a surface end to end: atlas, energies, supports, solve, fields.

For quadratic energies Π(U) = ½ UᵀKU − FᵀU (K the kit's tangent, F = −R(0)), supports
C U = g by the augmented Lagrangian (thesis App. E.2), with weak springs on ghost DOFs
(:func:`.surface_model.ghost_springs`). The physics gives its ``fields``, ``energies(
positions)`` (the kernels, given the quadrature positions for source terms) and a list of
``supports`` ({field, components, where, value}); :class:`LinearPhysics` is the mixin
that gives a physics plugin ``solve``, ``evaluate`` and ``field_at_quadrature``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pointatlas.errors import ConfigError


@dataclass
class LinearSolution:
    """The solved problem: model, layout, assembler, nodal values U (n_nodes, block)."""

    model: object
    layout: object
    assembler: object
    nodal: np.ndarray
    info: object
    name: str

    def field_nodal(self, name: str) -> np.ndarray:
        return self.layout.split(self.nodal)[name]

    def evaluate(self, name: str, x) -> np.ndarray:
        """Field ``name`` at the surface points nearest to ``x`` (k, components)."""
        from .surface_model import values_at

        return values_at(self.model.atlas, self.field_nodal(name), x)[0]

    def field_at_quadrature(self, name: str) -> dict:
        """{positions, weights, normals, values (m, c), gradients (m, c, 3)} of field
        ``name``: u_q and its surface gradient ∇_Γ u = a^αβ u_,β X_,α (1/length)."""
        q = self.model.quadrature
        Un = self.field_nodal(name)
        vals = q.interpolation() @ Un
        from scipy.sparse import csr_matrix

        d = [csr_matrix((q.basis[:, 1 + k], q.indices, q.indptr),
                        shape=(q.n_points, q.n_nodes)) @ Un for k in range(2)]
        A = q.inverse_metric
        grads = np.zeros((q.n_points, Un.shape[1], 3))
        for al in range(2):
            for be in range(2):
                grads += (A[:, al, be][:, None] * d[be])[:, :, None] * q.tangents[:, al][:, None]
        return dict(positions=q.positions, weights=q.weights, normals=q.normals,
                    values=vals, gradients=grads)

    def dataset(self):
        import xarray as xr

        m = self.model
        ds = xr.Dataset(attrs={"title": f"{self.name} on a point-set surface"})
        n = m.points.shape[0]
        from .surface_model import values_at_nodes

        for f in self.layout.fields:
            v = values_at_nodes(m.atlas, self.field_nodal(f.name), np.arange(n))
            dims = ("point",) if f.components == 1 else ("point", f"{f.name}_component")
            ds[f.name] = (dims, v[:, 0] if f.components == 1 else v,
                          {"long_name": f.long_name or f.name, "units": f.units})
        ds["n_dof"] = ((), self.layout.n_dofs, {"long_name": "degrees of freedom",
                                                "units": "1"})
        ds["n_patches"] = ((), len(m.atlas.charts_), {"long_name": "patches (charts)",
                                                      "units": "1"})
        ds["constraint_violation"] = ((), float(self.info.violation),
                                      {"long_name": "max |CU - g|", "units": "1"})
        return ds.assign_coords(point=("point", np.arange(n), {"long_name": "point of the cloud",
                                                             "units": "1"}))


def support_constraints(model, layout, supports):
    """(C, g) of all ``supports`` ({field, components, where, value}); value: a number or an
    expression of the coordinates."""
    from scipy.sparse import csr_matrix, vstack

    from .expression import evaluate_values
    from .selector_spec import Selector
    from .selectors import select
    from .supports import value_constraints

    rows, rhs = [], []
    for i, s in enumerate(supports):
        s = dict(s)
        name = s.get("field", layout.fields[0].name)
        where = s.get("where")
        if where is None:
            raise ConfigError(f"physics.supports[{i}] needs where: a selector of the points "
                              "it holds, e.g. {boundary: true}.")
        sel = where if isinstance(where, Selector) else Selector(**dict(where))
        nodes = select(sel, model.points, model.boundary, model.curves)  # sorted indices
        value = s.get("value", 0.0)
        if isinstance(value, str):
            value = evaluate_values(value, model.points[nodes])[:, None]
        C, g = value_constraints(model.atlas, layout, name, nodes, value, s.get("components"))
        rows.append(C)
        rhs.append(g)
    if not rows:
        return csr_matrix((0, layout.n_dofs)), np.zeros(0)
    return vstack(rows).tocsr(), np.concatenate(rhs)


def solve_linear_problem(physics, ctx, cloud, atlas_settings) -> LinearSolution:
    """Build, assemble and solve ``physics`` (see module doc) on ``cloud``."""
    from scipy.sparse import diags

    from pointatlas_solvers.augmented_lagrangian import solve_augmented

    from .assembler import Assembler
    from .fields import FieldLayout
    from .surface_model import atlas_factories, build_surface_model, ghost_springs

    name = ctx.choices.get("physics", type(physics).__name__) if ctx is not None else \
        type(physics).__name__
    order = max(f.order for f in physics.fields)
    model = build_surface_model(cloud, atlas_settings, **atlas_factories(ctx, atlas_settings,
                                                                         name),
                                order=order, ghost_layers=physics.ghost_layers,
                                block=sum(f.components for f in physics.fields), log=ctx.log)
    layout = FieldLayout(physics.fields, model.nodes.shape[0])
    A = Assembler(model.quadrature, layout, physics.energies(model.quadrature.positions))
    zero = np.zeros(layout.n_dofs)
    _, R0 = A.residual(zero)
    K = A.tangent(zero)
    K = (K + diags(ghost_springs(K.diagonal(), model, layout.block))).tocsr()
    C, g = support_constraints(model, layout, physics.supports)
    U, _, info = solve_augmented(K, -R0, C, g, physics.penalty, physics.constraint_tol,
                                 backend=physics.solver)
    if ctx is not None:
        ctx.log.info("%s: %d DOF, %d constraint rows, violation %.2e", name, layout.n_dofs,
                     C.shape[0], info.violation)
    return LinearSolution(model, layout, A, layout.as_blocks(U), info, name)


class LinearPhysics:
    """Mixin: ``solve``, ``evaluate``, ``field_at_quadrature`` and ``discrete_energy`` of a
    linear kit physics."""

    def discrete_energy(self, patch: dict):
        """The physics' energies on quadrature arrays (:class:`.energy.DiscreteEnergy`)."""
        from .energy import DiscreteEnergy

        return DiscreteEnergy(self.fields, self.energies(patch["positions"]), patch)

    def solve(self, ctx, *, cloud, atlas_settings):
        """Solve on ``cloud``; returns the fields at the points (xr.Dataset)."""
        from pointatlas_solvers.linear_backends import resolve_backend

        self.solution_ = solve_linear_problem(self, ctx, cloud, atlas_settings)
        ds = self.solution_.dataset()
        ds.attrs["linear_solver"] = resolve_backend(self.solver)  # 'auto' resolved
        return ds

    def evaluate(self, name: str, x) -> np.ndarray:
        return self._solved().evaluate(name, x)

    def field_at_quadrature(self, name: str) -> dict:
        return self._solved().field_at_quadrature(name)

    def _solved(self) -> LinearSolution:
        if getattr(self, "solution_", None) is None:
            from pointatlas.errors import PointatlasError

            raise PointatlasError(f"{type(self).__name__} is not solved yet: call solve first.")
        return self.solution_
