"""Pictures of shell results Datasets: the deformed shape and energy-density snapshots.

Thesis Fig. 16 and Fig. 18 (§4.4, Paper 2 §5) show snapshots of a shell along its load path,
the deformed points (not magnified) coloured by the strain energy density; the linear
study's picture is the deformed shape coloured by |u|. They read only the Dataset (dims
``point``, ``dim``, ``increment``), rendered off screen by pyvista.
"""
from __future__ import annotations

import os

import numpy as np

from pointatlas.errors import InputError


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
                    cmap: str = "viridis", clim=None, bar_title: str = "energy density",
                    view: str = "isometric") -> bytes:
    """PNG bytes: up to 4 off-screen pyvista views of the deformed points x_a + u_a (not
    magnified, thesis Fig. 16/18) coloured by the energy density, one colour range and one
    scalar bar ("energy density", energy per reference area) shared by all views.

    points : (n, 3) reference positions (length);  displacements : list of (n, 3) u_a;
    densities : list of (n,) densities or (n, 3) arrays (the 'total' column is used);
    titles : list of str, one per view (VTK's fonts draw Latin-1 only: write "lambda", not
        "λ");  window : (width, height) pixels, default 600 × 500 per view.
    With log_scale, values below max·1e-6 (zeros included) are drawn at that floor.
    ``clim`` (lo, hi) fixes the colour range (e.g. (0, 1) for a phase field) instead of the
    shared percentile range; ``bar_title`` names the scalar bar; ``view`` 'isometric' or
    'xy' (a flat specimen seen from above).
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
    lo, hi = _shared_range(vals, log_scale) if clim is None else map(float, clim)
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
        cloud.point_data[bar_title] = np.clip(v, lo, None) if log_scale else v
        last = i == k - 1
        bar = {**_BAR, "title": bar_title, **({} if log_scale else {"fmt": "%.2f"})}
        plotter.add_mesh(cloud, scalars=bar_title, clim=(lo, hi), cmap=cmap,
                         log_scale=log_scale, render_points_as_spheres=True,
                         point_size=point_size, nan_color="grey", show_scalar_bar=last,
                         scalar_bar_args=bar if last else None)
        plotter.add_text(str(title), font_size=10, color="black", position="upper_edge")
        bounds[0::2] = np.fmin(bounds[0::2], x.min(axis=0))
        bounds[1::2] = np.fmax(bounds[1::2], x.max(axis=0))
    plotter.link_views()  # one camera for all views, framing every configuration
    plotter.view_xy() if view == "xy" else plotter.view_isometric()
    plotter.reset_camera(bounds=bounds)
    image = plotter.screenshot(return_img=True)
    plotter.close()
    buf = io.BytesIO()
    plt.imsave(buf, image, format="png")
    return buf.getvalue()


def deformed_picture(ds, window=(900, 700)) -> bytes:
    """Off-screen pyvista picture (PNG bytes) of a results Dataset: the deformed surface
    (``surface_triangle``; the points when there is none), displacement drawn at
    ``attrs['magnification']`` times its size, coloured by |u| with its units, and the
    undeformed surface's edges in grey."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import io

    import matplotlib.pyplot as plt
    import pyvista as pv

    x = ds["position"].values
    u = ds["displacement_field"].values
    mag = float(ds.attrs.get("magnification", 1.0))
    units = str(ds["displacement_field"].attrs.get("units", ""))
    title = f"u magnitude [{units}]" if units and units != "1" else "u magnitude"
    bar = {"title": title, "color": "black", "vertical": True, "position_x": 0.80,
           "position_y": 0.15, "height": 0.7, "width": 0.06, "title_font_size": 18,
           "label_font_size": 14, "fmt": "%.3g"}
    plotter = pv.Plotter(off_screen=True, window_size=window)
    plotter.set_background("white")
    if "surface_triangle" in ds and ds.sizes.get("triangle", 0):
        tri = np.asarray(ds["surface_triangle"].values, np.int64)
        faces = np.hstack([np.full((len(tri), 1), 3), tri]).ravel()
        before = pv.PolyData(np.ascontiguousarray(x), faces)
        after = pv.PolyData(np.ascontiguousarray(x + mag * u), faces)
        after.point_data[title] = np.linalg.norm(u, axis=1)
        plotter.add_mesh(before.extract_all_edges(), color="grey", opacity=0.25, line_width=1)
        plotter.add_mesh(after, scalars=title, cmap="viridis", smooth_shading=True,
                         scalar_bar_args=bar)
    else:
        cloud = pv.PolyData(np.ascontiguousarray(x + mag * u))
        cloud.point_data[title] = np.linalg.norm(u, axis=1)
        plotter.add_mesh(cloud, scalars=title, render_points_as_spheres=True, point_size=8,
                         cmap="viridis", scalar_bar_args=bar)
    plotter.view_isometric()
    plotter.camera.zoom(0.85)  # room for the colour bar
    image = plotter.screenshot(return_img=True)
    plotter.close()
    buf = io.BytesIO()
    plt.imsave(buf, image, format="png")
    return buf.getvalue()
