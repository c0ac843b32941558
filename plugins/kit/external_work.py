"""External work as an energy: dead loads and sources on any field, on three quadratures.

The work of a dead load s on a field u is W_ext = ∫ s · u, an energy linear in the field's
values (:class:`.energy.LinearSource`, density −s·u). Its nodal forces are
F = −∂Π_ext/∂U = −R(0), assembled by the kit's one :class:`.assembler.Assembler`
(thesis L363–520, Paper 1 §3):

* per unit area (surface force q, pressure p n): the atlas quadrature, weights w_g J ψ_κ
  (thesis Eq. 14) — F_a = Σ_g w_g p_a(ξ_g) q_g;
* per unit length along boundary curves: the boundary nodes, each in its best chart,
  weighted by its share ℓ_i of the curve (trapezoidal rule) — F_a = Σ_i ℓ_i p_a(x_i) t;
* concentrated (a point force, a point source): one chart point of weight 1 —
  F_a = p_a(ξ) P.

:func:`load_vector` scatters the forces into the DOF vector of any
:class:`.fields.FieldLayout`, so a load names the field it acts on (the shell's
displacement, a phase field, a temperature) and nothing here knows a physics.
"""
from __future__ import annotations

import numpy as np

from pointatlas.errors import ConfigError, InputError

from .atlas_quadrature import AtlasQuadrature


def chart_point_quadrature(atlas, chart, xi, weights) -> AtlasQuadrature:
    """An order-0 :class:`.atlas_quadrature.AtlasQuadrature` at chart points
    (chart[i], xi[i]) with the given ``weights`` (k,) (length units of the measure they
    stand for: 1 for a point, length for a line, area for a surface), with the reference
    position X = Σ p_a P_a (the chart's control points), tangents and the atlas's
    orientation there.

    A point outside its chart's domain is an :class:`InputError` naming it
    (:func:`pointatlas_atlas.evaluation.basis_at`)."""
    from pointatlas_atlas.chart import chart_derivatives

    chart = np.asarray(chart, np.int64).ravel()
    xi = np.atleast_2d(np.asarray(xi, np.float64))
    weights = np.asarray(weights, np.float64).ravel()
    if not (len(chart) == len(xi) == len(weights)):
        raise InputError(f"chart_point_quadrature: {len(chart)} charts, {len(xi)} points "
                         f"and {len(weights)} weights; give one of each per point.")
    from pointatlas_atlas.evaluation import stack_rows
    from pointatlas_atlas.partition import label_groups

    X, T = np.zeros((len(chart), 3)), np.zeros((len(chart), 2, 3))
    parts, rows = [], []
    for k, sel in label_groups(chart):
        c = atlas.charts_[k]
        b = c.approximant.evaluate(xi[sel], order=1)
        if b.outside is not None and b.outside.any():
            i = sel[np.flatnonzero(b.outside)[0]]
            raise InputError(f"load point {i} (ξ = {xi[i].tolist()}) lies outside chart "
                             f"{k}'s domain; a load must act on the sampled surface.")
        X[sel], T[sel], _ = chart_derivatives(b, c.control_points, 1)
        parts.append(b.renumbered(c.node_index))
        rows.append(sel)
    if not parts:
        raise InputError("chart_point_quadrature: no point given.")
    basis = stack_rows(parts, np.concatenate(rows))   # rows back in the input order
    signs = np.asarray(getattr(atlas, "chart_orientation_", np.ones(len(atlas.charts_))),
                       float)
    return AtlasQuadrature(
        indptr=basis.indptr, indices=basis.indices, basis=basis.values[:, None],
        weights=weights, chart=chart, positions=X, tangents=T, second=None,
        orientation=signs[chart], n_nodes=atlas.points_.shape[0])


def node_point_quadrature(atlas, nodes, weights) -> AtlasQuadrature:
    """:func:`chart_point_quadrature` at control points ``nodes``, each in its best chart
    (largest ψ_κ, :func:`pointatlas_atlas.evaluation.node_charts`) at its own ξ."""
    from pointatlas_atlas.evaluation import node_charts

    nodes = np.asarray(nodes, np.int64).ravel()
    chart, local = node_charts(atlas, nodes)
    dim = atlas.charts_[0].xi_nodes.shape[1]
    xi = (np.stack([atlas.charts_[k].xi_nodes[j] for k, j in zip(chart, local)])
          if len(nodes) else np.zeros((0, dim)))
    return chart_point_quadrature(atlas, chart, xi, weights)


def load_vector(layout, name: str, quadrature, values) -> np.ndarray:
    """Nodal forces (n_nodes, block) of the dead load ``values`` on field ``name``.

    ``values``: (m, components) load per unit of the quadrature's measure at its m points,
    or one (components,) vector for all; F = −R(0) of :class:`.energy.LinearSource`
    assembled on ``quadrature`` for the field's values only, placed in the field's columns
    of the layout's DOF blocks (dof = B a + offset + i)."""
    from .assembler import Assembler
    from .energy import LinearSource
    from .fields import Field, FieldLayout

    f = layout.field(name)
    if quadrature.n_nodes != layout.n_nodes:
        raise ConfigError(f"the load's quadrature has {quadrature.n_nodes} nodes, the field "
                          f"layout {layout.n_nodes}.")
    s = np.asarray(values, np.float64)
    if s.ndim == 1 and s.size == f.components:
        s = np.broadcast_to(s, (quadrature.n_points, f.components))
    if s.shape != (quadrature.n_points, f.components):
        raise ConfigError(f"a load on field {name!r} ({f.components} component(s)) needs "
                          f"{f.components} value(s) per point; got shape {s.shape} for "
                          f"{quadrature.n_points} point(s).")
    if not np.all(np.isfinite(s)):
        raise InputError(f"the load on field {name!r} has NaN or inf values.")
    values_only = Field(f.name, f.components, order=0, units=f.units, long_name=f.long_name)
    sub = FieldLayout((values_only,), layout.n_nodes)
    _, R = Assembler(quadrature, sub, [LinearSource(values_only, s)]).residual(
        np.zeros(sub.n_dofs))
    F = np.zeros((layout.n_nodes, layout.block))
    o = layout.offsets[name]
    F[:, o:o + f.components] = -R.reshape(layout.n_nodes, f.components)
    return F
