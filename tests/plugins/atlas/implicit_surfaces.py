"""Point clouds made here, independently of plugins/sources/: implicit surfaces f = 0 sampled
by Newton projection of random points and farthest-point thinning, and their marching-cubes
reference areas (pyvista). Used by the chart-repair tests of the atlas and the studies."""
from __future__ import annotations

import numpy as np


def torus_tube(x: np.ndarray, R: float, r: float, centre_x: float = 0.0):
    """Signed distance to the torus of radii (R, r) round the z axis through (centre_x, 0, 0)
    and its gradient (unit where defined): f = sqrt((ρ − R)² + z²) − r."""
    dx, dy, z = x[:, 0] - centre_x, x[:, 1], x[:, 2]
    rho = np.maximum(np.hypot(dx, dy), 1e-300)
    s = rho - R
    d = np.maximum(np.hypot(s, z), 1e-300)
    grad = np.stack([s / d * dx / rho, s / d * dy / rho, z / d], axis=1)
    return d - r, grad


def figure_eight_tube(x: np.ndarray, R: float = 0.5, r: float = 0.075, blend: float = 0.06):
    """A genus-2 surface: the tube of radius r round two circles of radius R tangent at the
    origin (a figure eight in the plane z = 0), their union smoothed over ``blend``:
    f = −blend·log(e^{−d₁/blend} + e^{−d₂/blend}) − r, d_i the distance to circle i."""
    (f1, g1), (f2, g2) = torus_tube(x, R, 0.0, -R), torus_tube(x, R, 0.0, R)
    m = np.minimum(f1, f2)
    e1, e2 = np.exp(-(f1 - m) / blend), np.exp(-(f2 - m) / blend)
    f = m - blend * np.log(e1 + e2) - r
    grad = (e1[:, None] * g1 + e2[:, None] * g2) / (e1 + e2)[:, None]
    return f, grad


def sample_level_set(func, lo, hi, n: int, seed: int = 0, oversample: int = 4,
                     band: float = 0.05) -> np.ndarray:
    """n quasi-uniform points on func(x)[0] = 0 inside the box [lo, hi]: uniform random points
    within ``band`` of the surface, Newton-projected (x ← x − f ∇f/|∇f|²), then thinned by
    greedy farthest-point sampling from ``oversample``·n projected points."""
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    found, need = [], n * oversample
    while sum(len(p) for p in found) < need:
        x = rng.uniform(lo, hi, (4 * need, 3))
        x = x[np.abs(func(x)[0]) < band]
        for _ in range(10):
            f, g = func(x)
            x = x - (f / np.maximum(np.sum(g * g, axis=1), 1e-300))[:, None] * g
        found.append(x[np.abs(func(x)[0]) < 1e-10])
    X = np.concatenate(found)[:need]
    keep = np.empty(n, np.int64)
    keep[0] = 0
    dist = np.sum((X - X[0]) ** 2, axis=1)
    for a in range(1, n):
        keep[a] = int(np.argmax(dist))
        np.minimum(dist, np.sum((X - X[keep[a]]) ** 2, axis=1), out=dist)
    return X[keep]


def marching_cubes_area(func, lo, hi, spacing: float) -> tuple[float, int]:
    """Area of the marching-cubes mesh of func = 0 on a grid of the given spacing in [lo, hi]
    and the Euler characteristic of the mesh (V − E + F)."""
    import pyvista as pv

    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    dims = np.ceil((hi - lo) / spacing).astype(int) + 1
    grid = pv.ImageData(dimensions=dims, spacing=(spacing,) * 3, origin=lo)
    grid.point_data["f"] = func(np.asarray(grid.points))[0]
    mesh = grid.contour([0.0], scalars="f").triangulate().clean()
    euler = mesh.n_points - mesh.extract_all_edges().n_cells + mesh.n_cells
    return float(mesh.area), int(euler)


def figure_eight_box(R: float = 0.5, r: float = 0.075, blend: float = 0.06):
    """A box holding the figure-eight tube with a margin (the blend bulges it by ≤ blend·ln 2)."""
    m = 1.5 * r + blend
    return np.array([-2 * R - m, -R - m, -m]), np.array([2 * R + m, R + m, m])
