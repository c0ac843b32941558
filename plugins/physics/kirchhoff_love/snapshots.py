"""Energy density at the sampled points and pictures of it on deformed configurations.

Thesis Fig. 16 and Fig. 18 (§4.4, Paper 2 §5) show snapshots of a shell along its load path,
the deformed points (not magnified) coloured by the strain energy density. Here

    w(x_a) = w_m + w_b,   w_m = ½ h eᵀ D e,   w_b = ½ h³/12 kᵀ D k     (energy/length²)

per unit reference area, evaluated with the geometrically exact kinematics of nonlinear.py
(Green membrane strain e, bending strain k = B − b; point_kernels.py, thesis §4.2) at every
sampled point x_a itself: each point is evaluated in its best chart (largest ψ_κ, see
pointatlas_atlas.evaluation.node_charts) at its own embedded coordinates ξ_a = Ξ_κ[a], with
the reference derivatives X_,α, X_,αβ of that chart φ_κ = Σ p_b C_b (as the quadrature of
build_model does). A rigid motion gives w = 0.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from pointatlas.errors import InputError

from .assembly import densities_and_forces
from .material import ShellMaterial
from .quadrature_data import ShellQuadrature, concatenate, from_basis

DENSITY_COLUMNS = ("membrane", "bending", "total")
"""Columns of the array returned by PointEnergyOperator (energy per reference area)."""


@dataclass
class PointEnergyOperator:
    """U (N+G, 3) → (n_points, 3) energy density per unit reference area at the sampled points.

    quadrature : ShellQuadrature whose points are the sampled points with a defined basis
        (unit weights; the weights are not used for densities)
    rows : (m,) output row (sampled point index) of each quadrature point
    n_points : number of sampled points; rows of points where the chart's LME basis is
        undefined (flagged outside the chart; normally none) are NaN
    """

    quadrature: ShellQuadrature
    material: ShellMaterial
    rows: np.ndarray
    n_points: int

    @property
    def n_undefined(self) -> int:
        return self.n_points - len(self.rows)

    def __call__(self, U) -> np.ndarray:
        """(n_points, 3) float64: membrane, bending, total (energy/length², e.g. N/m)."""
        q = self.quadrature
        dens, _ = densities_and_forces(q, self.material, q.check_displacements(U), False)
        out = np.full((self.n_points, 3), np.nan)
        out[self.rows, :2] = dens
        out[self.rows, 2] = dens.sum(axis=1)
        return out


def point_energy_operator(model) -> PointEnergyOperator:
    """Build, once, the quadrature at the sampled points of a ShellModel (build_model).

    Basis values, first and second chart derivatives of every sampled point in its best
    chart; reference tangents and second derivatives from that chart's control points
    (thesis Eq. 2, §4.2). Each call of the result is one pass of the numba kernel.
    """
    from pointatlas_atlas.chart import chart_derivatives
    from pointatlas_atlas.evaluation import node_charts

    atlas, n_nodes = model.atlas, model.nodes.shape[0]
    n_points = model.points.shape[0]
    model.material.check()
    chart, local = node_charts(atlas, np.arange(n_points))
    parts, rows = [], []
    for k in np.unique(chart):
        sel = np.flatnonzero(chart == k)
        c = atlas.charts_[k]
        b = c.approximant.evaluate(c.xi_nodes[local[sel]], order=2)
        if b.outside is not None and b.outside.any():
            keep = np.flatnonzero(~b.outside)
            b, sel = b.take(keep), sel[keep]
        if len(sel) == 0:
            continue
        _, T, S = chart_derivatives(b, c.control_points, 2)
        parts.append(from_basis(b, T, S, np.ones(len(sel)), k, n_nodes,
                                node_index=c.node_index))
        rows.append(sel)
    if not parts:
        raise InputError("no sampled point has a defined basis in its chart; the atlas "
                         "cannot evaluate the energy density (check the LME settings).")
    return PointEnergyOperator(concatenate(parts), model.material, np.concatenate(rows),
                               n_points)


def pick_snapshots(n_increments: int, k: int = 4) -> list[int]:
    """k increment indices at load-path fractions 1/k, 2/k, …, 1 (the last one always).

    All indices if n_increments ≤ k; e.g. (10, 4) → [2, 4, 7, 9].
    """
    for name, v in (("n_increments", n_increments), ("k", k)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise InputError(f"pick_snapshots: {name} = {v!r} is invalid; give an integer >= 1.")
    n, k = int(n_increments), int(k)
    if n <= k:
        return list(range(n))
    return sorted({-(-(j + 1) * n // k) - 1 for j in range(k)})


_BAR = {"title": "energy density", "color": "black", "vertical": False, "fmt": "%.1e",
        "n_labels": 4, "position_x": 0.15, "position_y": 0.03, "width": 0.7, "height": 0.1,
        "title_font_size": 14, "label_font_size": 12}
"""Scalar bar (one, in the last view) shared by all views: horizontal, along the bottom."""


def _shared_range(values: list[np.ndarray], log_scale: bool) -> tuple[float, float]:
    """Colour range over all snapshots, up to the 99.5th percentile (a few outlying point
    values must not wash out the picture); for a log scale the floor is hi·1e-6 (or the
    smallest positive value if larger)."""
    allv = np.concatenate([v[np.isfinite(v)] for v in values] + [np.zeros(0)])
    hi = float(np.percentile(allv, 99.5)) if allv.size else 1.0
    allv = np.minimum(allv, hi)
    if log_scale:
        pos = allv[allv > 0]
        if not pos.size:
            return 1e-12, 1.0
        lo = max(float(pos.min()), float(pos.max()) * 1e-6)
        return lo, max(hi, lo * 10.0)
    lo = float(allv.min()) if allv.size else 0.0
    return lo, hi if hi > lo else lo + 1.0


def snapshot_figure(points, displacements, densities, titles, window=None,
                    log_scale: bool = True, point_size: float = 6.0,
                    cmap: str = "viridis") -> bytes:
    """PNG bytes: up to 4 off-screen pyvista views of the deformed points x_a + u_a (not
    magnified, thesis Fig. 16/18) coloured by the energy density, one colour range and one
    scalar bar ("energy density", energy per reference area) shared by all views.

    points : (n, 3) reference positions (length);  displacements : list of (n, 3) u_a;
    densities : list of (n,) densities or (n, 3) arrays (the 'total' column is used);
    titles : list of str, one per view (VTK's fonts draw Latin-1 only: write "lambda", not
        "λ");  window : (width, height) pixels, default 600 × 500 per view.
    With log_scale, values below max·1e-6 (zeros included) are drawn at that floor.
    """
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import io

    import matplotlib.pyplot as plt
    import pyvista as pv

    X = np.asarray(points, dtype=np.float64)
    k = len(displacements)
    if not 1 <= k <= 4 or len(densities) != k or len(titles) != k:
        raise InputError(f"snapshot_figure needs 1 to 4 snapshots with one displacement, "
                         f"density and title each; got {k}, {len(densities)}, {len(titles)}.")
    vals = []
    for d in densities:
        d = np.asarray(d, dtype=np.float64)
        vals.append(d[:, -1] if d.ndim == 2 else d)
    for u, v in zip(displacements, vals):
        if np.shape(u) != X.shape or v.shape != (X.shape[0],):
            raise InputError(f"snapshot arrays must have shapes {X.shape} (displacement) and "
                             f"({X.shape[0]},) (density); got {np.shape(u)}, {v.shape}.")
    lo, hi = _shared_range(vals, log_scale)
    shape = (2, 2) if k == 4 else (1, k)
    if window is None:
        window = (600 * shape[1], 500 * shape[0])
    plotter = pv.Plotter(shape=shape, off_screen=True, window_size=tuple(window),
                         border=False)
    plotter.set_background("white")
    bounds = np.full(6, np.nan)
    for i, (u, v, title) in enumerate(zip(displacements, vals, titles)):
        plotter.subplot(*divmod(i, shape[1]))
        x = X + np.asarray(u, dtype=np.float64)
        cloud = pv.PolyData(np.ascontiguousarray(x))
        cloud.point_data["energy density"] = np.clip(v, lo, None) if log_scale else v
        last = i == k - 1
        plotter.add_mesh(cloud, scalars="energy density", clim=(lo, hi), cmap=cmap,
                         log_scale=log_scale, render_points_as_spheres=True,
                         point_size=point_size, nan_color="grey", show_scalar_bar=last,
                         scalar_bar_args=dict(_BAR) if last else None)
        plotter.add_text(str(title), font_size=10, color="black", position="upper_edge")
        bounds[0::2] = np.fmin(bounds[0::2], x.min(axis=0))
        bounds[1::2] = np.fmax(bounds[1::2], x.max(axis=0))
    plotter.link_views()  # one camera for all views, framing every configuration
    plotter.view_isometric()
    plotter.reset_camera(bounds=bounds)
    image = plotter.screenshot(return_img=True)
    plotter.close()
    buf = io.BytesIO()
    plt.imsave(buf, image, format="png")
    return buf.getvalue()
