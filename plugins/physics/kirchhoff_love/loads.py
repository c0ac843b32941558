"""The shell's loads as external work on its displacement field (Paper 1 §3, thesis
L363–520), assembled by the kit (:mod:`pointatlas_kit.external_work`: F = −∂Π_ext/∂U):

* point force P at a surface point x: F_a = p_a(ξ) P, with (κ, ξ) the chart preimage of the
  closest-point projection of the given point (Paper 2 App. A);
* surface force q per unit area (self weight): F_a = Σ_g w_g p_a(ξ_g) q, with the atlas
  quadrature weights w_g = w J ψ_κ (thesis §3.4);
* pressure p along the unit normal: q = p n;
* line force t per unit length on boundary points: trapezoidal lengths along the ordered
  boundary curve, F_a = Σ_i ℓ_i p_a(x_i) t.

What is the shell's here: the refusals (a point load off the surface, a line load with no
segment) and the geometry of where the load acts.
"""
from __future__ import annotations

import numpy as np

from pointatlas.errors import InputError

from pointatlas_kit.external_work import chart_point_quadrature, load_vector, node_point_quadrature
from pointatlas_kit.fields import FieldLayout
from pointatlas_kit.selectors import describe, select

from .displacement_field import DISPLACEMENT


def _forces(quadrature, values) -> np.ndarray:
    """(N, 3) nodal forces of ``values`` per unit measure on the displacement."""
    return load_vector(FieldLayout((DISPLACEMENT,), quadrature.n_nodes), DISPLACEMENT.name,
                       quadrature, values)


def _vec(v) -> str:
    return "[" + ", ".join(f"{c:.6g}" for c in np.asarray(v, dtype=np.float64).ravel()) + "]"


def point_load(atlas, at, force, spacing: float, max_offset: float, points=None):
    """(F (N, 3), projected point, distance) of a point force at the surface point nearest
    ``at`` (closest-point projection, Paper 2 App. A).

    More than ``max_offset`` spacings (``spacing``: median point spacing h, length units)
    off the surface is an :class:`InputError` giving the distance, the nearest surface point
    and h. When the projection fails (no chart reaches the point), the distance is the one
    to the nearest of ``points`` (default: the atlas's nodes; pass the sampled points so that
    ghosts are not proposed).
    """
    from pointatlas_atlas.projection import closest_point

    x = np.asarray(at, dtype=np.float64).reshape(1, 3)
    proj = closest_point(atlas, x, on_failure="flag")
    converged = bool(proj.converged[0]) and np.isfinite(proj.distance[0])
    allowed = max_offset * spacing
    if converged and float(proj.distance[0]) <= allowed:
        q = chart_point_quadrature(atlas, proj.chart, proj.xi, np.ones(1))
        return _forces(q, np.asarray(force, dtype=np.float64)), proj.point[0], \
            float(proj.distance[0])
    if converged:
        dist, nearest = float(proj.distance[0]), proj.point[0]
        where = f"the nearest surface point is {_vec(nearest)}"
        other = f", or raise physics.max_load_offset (now {max_offset:g})"
    else:
        P = np.asarray(atlas.points_ if points is None else points, dtype=np.float64)
        d = np.linalg.norm(P - x, axis=1)
        dist, nearest = float(d.min()), P[int(np.argmin(d))]
        where = ("the closest-point projection onto the surface failed (no chart reaches the "
                 f"point), so this is the distance to the nearest sampled point {_vec(nearest)}")
        other = ""
    raise InputError(
        f"the load point {_vec(x)} is {dist:.3g} off the surface ({dist / spacing:.3g} "
        f"spacings; {where}; spacing h = {spacing:.3g}, a point load must lie within "
        f"{allowed:.3g} = {max_offset:g} h of the surface). Fix: move the load point onto the "
        f"surface, e.g. at: {_vec(nearest)} (check the coordinates and the model: full, "
        f"quarter or eighth){other}.")


def surface_load(quadrature, n_nodes: int, force=None, pressure=None, normals=None):
    """Consistent nodal forces (n_nodes, 3) of a load per unit area (vector ``force`` or
    ``pressure``·n with ``normals`` (m, 3) at the quadrature points)."""
    if quadrature.n_nodes != n_nodes:
        raise InputError(f"surface_load: the quadrature has {quadrature.n_nodes} nodes, "
                         f"not {n_nodes}.")
    if pressure is not None:
        traction = float(pressure) * np.asarray(normals, dtype=np.float64)
    else:
        traction = np.asarray(force, dtype=np.float64)
    return _forces(quadrature, traction)


def line_load(atlas, points, boundary, curves, where, force, spacing: float):
    """Nodal forces of a force per unit length on the boundary points ``where`` selects
    (``spacing``: median point spacing; longer steps along a curve are not segments)."""
    nodes = select(where, points, boundary, curves)
    from pointatlas_atlas.boundary import curve_segments

    picked = np.zeros(points.shape[0], bool)
    picked[nodes] = True
    seg = curve_segments(points, curves, 2.0 * spacing)
    seg = seg[picked[seg[:, 0]] & picked[seg[:, 1]]]
    ell = np.linalg.norm(points[seg[:, 0]] - points[seg[:, 1]], axis=1)
    length = 0.5 * (np.bincount(seg[:, 0], ell, points.shape[0])
                    + np.bincount(seg[:, 1], ell, points.shape[0]))
    if not length[nodes].any():
        raise InputError(f"the line load on {describe(where)} selects {len(nodes)} boundary "
                         "point(s) but no boundary segment between them: select a stretch of "
                         "a boundary curve (at least two neighbouring boundary points).")
    q = node_point_quadrature(atlas, nodes, length[nodes])
    return _forces(q, np.asarray(force, dtype=np.float64))
