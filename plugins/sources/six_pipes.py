"""Six connected open pipes: three orthogonal pipes crossing at one smooth junction (thesis
Fig. 17, the brittle thin shell of §4.4 of the introduction).

The thesis gives the figure's dimensions only (pipe length L = 3, diameter D = 0.95, h =
0.005) and took its point set from the MATLAB Central File Exchange; this source builds a
smooth stand-in: pipes of radius r = D/2 along the x, y and z axes, each of length L (its
ends at ±H, H = L/2: six open ends, the "six pipes" being the six arms from the junction),
blended by the C² cubic smooth minimum of :mod:`.open_pipes` with blend radius k:

    F(x) = smin(smin(d_x, d_y), d_z) − r,   d_x = sqrt(y² + z²)  (distance to the x axis) …

cut to max(|x|, |y|, |z|) ≤ H. Outside the junction box max |x_i| ≤ c, c = r + k + 0.1, F
is the distance to one axis minus r (|d_i − d_j| ≥ c − r > k there), so the arms end in
plain cylinders. A sphere with six holes: genus 0, χ = 2 − 6 = −4, six boundary circles.
The surface is mirror symmetric about x = 0, y = 0, z = 0 and the diagonal planes.

Area: A = 6·2πr(H − c) + A_box, A_box the area inside the junction box from a marching-cubes
mesh (pyvista) on grids of spacing r/24 and r/48 whose planes include the box faces,
vertices projected onto F = 0, Richardson-extrapolated (:func:`junction_box_area`). For the
defaults A = 18.66924 (A_box = 6.537193; spacings r/32 and r/64 give 6.537199; a Monte Carlo
estimate of the shell volume |F| < 0.01|∇F| in the box, independent of the mesh, 6.5234:
tests/plugins/sources/test_six_pipes.py).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar, Optional

import numpy as np

from pointatlas.pointcloud import PointCloud
from pointatlas.stores_config import stores_config

from .farthest_point import farthest_point_order
from .level_set import near_level_set, project_to_level_set
from .open_pipes import OVERSAMPLING, RING_SPACING, _smin, load_pipes
from .shell_source import JITTER
from .surface_source import COMMON_CONSTRAINTS, POSITIVE, SurfaceSource, require

#: Half-width of the candidate shell around F = 0, as a fraction of the pipe radius.
SHELL_HALF_WIDTH = 0.02
#: Fewest points on an end circle.
MIN_RING_POINTS = 8
#: structured sampling: candidates closer than this many spacings h to x = 0 are put on it
MIRROR_SNAP = 0.3


def _axis_distance(X, axis: int):
    """Distance to the coordinate axis ``axis`` and its gradient."""
    Y = X.copy()
    Y[:, axis] = 0.0
    d = np.maximum(np.linalg.norm(Y, axis=1), 1e-300)
    return d, Y / d[:, None]


def six_pipes_value_gradient(X: np.ndarray, r: float, k: float):
    """F (n,) and ∇F (n, 3) of the module docstring at the rows of X (length units)."""
    X = np.asarray(X, dtype=np.float64)
    F, G = _axis_distance(X, 0)
    for axis in (1, 2):
        F, G = _smin(F, G, *_axis_distance(X, axis), k)
    return F - r, G


def project_to_surface(X, r: float, k: float, tol: float = 1e-13, max_iter: int = 50):
    """Newton steps along ∇F until |F| ≤ tol·r."""
    return project_to_level_set(X, lambda Y: six_pipes_value_gradient(Y, r, k), tol * r,
                                max_iter)


def junction_box_half_size(r: float, k: float) -> float:
    """c = r + k + 0.1 r: beyond max |x_i| = c the arms are plain cylinders."""
    return r + k + 0.1 * r


def _box_mesh_area(r: float, k: float, g: float) -> float:
    """Area of F = 0 inside [−c, c]³ from a marching-cubes mesh of spacing ≈ g."""
    import pyvista as pv

    c = junction_box_half_size(r, k)
    dims = np.full(3, int(np.ceil(2 * c / g)) + 1)
    spacing = np.full(3, 2 * c / (dims[0] - 1))
    grid = pv.ImageData(dimensions=dims, spacing=spacing, origin=(-c, -c, -c))
    grid["F"] = six_pipes_value_gradient(np.asarray(grid.points), r, k)[0]
    mesh = grid.contour([0.0], scalars="F").triangulate()
    mesh.points = project_to_surface(np.asarray(mesh.points, dtype=np.float64), r, k, 1e-13,
                                     30)
    return float(mesh.area)


@lru_cache(maxsize=16)
def junction_box_area(r: float, k: float, g_fraction: float = 1.0 / 24.0) -> float:
    """A_box (module doc): Richardson from grid spacings g = g_fraction·r and g/2."""
    coarse = _box_mesh_area(r, k, g_fraction * r)
    fine = _box_mesh_area(r, k, 0.5 * g_fraction * r)
    return (4.0 * fine - coarse) / 3.0


def six_pipes_area(r: float, H: float, k: float) -> float:
    """A = 6·2πr(H − c) + A_box (module doc)."""
    c = junction_box_half_size(r, k)
    return 12.0 * np.pi * r * (H - c) + junction_box_area(r, k)


@stores_config
class SixPipes(SurfaceSource):
    """Three orthogonal pipes crossing at a smooth junction: six open ends at ±H on each axis.

    Sampling as :class:`~pointatlas_sources.open_pipes.OpenPipes`: structured, a Halton
    sequence in a thin shell around F = 0 projected onto it and thinned by farthest-point
    selection on the half x ≥ 0, then mirrored (the cloud is mirror symmetric about x = 0
    point for point, so a solution's symmetry can be measured at the points), plus the six
    end circles sampled exactly (symmetric too); random, uniform shell samples from
    ``rng`` and jittered end circles. Exactly n_points points; markers n_points // 4 by
    default. Exact: area (module doc), χ = −4, genus 0, 6 boundary curves, spacing h.
    """

    @dataclass
    class Config:
        n_points: int = 3000
        sampling: str = "structured"
        pipe_length: float = 3.0
        pipe_diameter: float = 0.95
        blend: float = 0.3
        n_markers: Optional[int] = None

        # each > 0; tied together in _check: blend k <= r = pipe_diameter/2, pipe_length/2
        # >= c + r/4 (plain cylinders beyond the junction box), n_points gives at least 8
        # points per end circle
        parameter_constraints: ClassVar[dict[str, list]] = {
            **COMMON_CONSTRAINTS, "pipe_length": POSITIVE, "pipe_diameter": POSITIVE,
            "blend": POSITIVE}

    description: ClassVar[str] = "Six connected open pipes (three crossing pipes, thesis Fig. 17)."
    name: ClassVar[str] = "six_pipes"

    def _geometry(self):
        return 0.5 * float(self.pipe_diameter), 0.5 * float(self.pipe_length), float(self.blend)

    def _check(self) -> None:
        r, H, k = self._geometry()
        require(k <= r, "blend", self.blend, f"must be in (0, pipe_diameter/2 = {r:g}]",
                f"Use a smaller blend, e.g. blend={0.5 * r:g}.")
        need = junction_box_half_size(r, k) + 0.25 * r
        require(H >= need, "pipe_length", self.pipe_length,
                f"must be >= {2 * need:g} so that the pipe ends are plain cylinders beyond "
                "the junction", f"Increase pipe_length to {2 * need:g} or lower the blend.")
        h = self.spacing(int(self.n_points))
        n_min = int(np.ceil(self._area() / (2 * np.pi * r / (RING_SPACING * MIN_RING_POINTS))
                            ** 2))
        require(2 * np.pi * r / (RING_SPACING * h) >= MIN_RING_POINTS - 0.5, "n_points",
                self.n_points, f"gives spacing h = {h:.3g}, too coarse for pipes of radius "
                f"{r:g} (fewer than {MIN_RING_POINTS} points around a pipe)",
                f"Use n_points >= {n_min}.")

    def _area(self) -> float:
        r, H, k = self._geometry()
        return six_pipes_area(r, H, k)

    def spacing(self, n: int) -> float:
        """h = sqrt(area / n) (length units)."""
        return float(np.sqrt(self._area() / n))

    def implicit_function(self, X: np.ndarray) -> np.ndarray:
        """F at the rows of X (≈ signed distance near the surface, length units)."""
        r, _, k = self._geometry()
        return six_pipes_value_gradient(X, r, k)[0]

    def end_circles(self, h: float, rng) -> np.ndarray:
        """Points on the six end circles (radius r, centre ±H on each axis), spacing ≈ h;
        ``rng`` None: equally spaced, else a random phase per circle and a jitter."""
        r, H, _ = self._geometry()
        m = max(MIN_RING_POINTS, 2 * int(round(np.pi * r / h)))  # even: mirror symmetric
        out = []
        for axis in range(3):
            a, b = [i for i in range(3) if i != axis]
            for end in (-H, H):
                theta = 2 * np.pi * np.arange(m) / m
                if rng is not None:
                    theta = theta + 2 * np.pi / m * (rng.uniform() + rng.uniform(
                        -0.5 * JITTER, 0.5 * JITTER, m))
                P = np.zeros((m, 3))
                P[:, axis], P[:, a], P[:, b] = end, r * np.cos(theta), r * np.sin(theta)
                out.append(P)
        return np.concatenate(out)

    def _interior(self, n: int, rng, clearance: float) -> np.ndarray:
        """n quasi-uniform points of the surface with max |x_i| ≤ H − clearance."""
        r, H, k = self._geometry()
        delta = SHELL_HALF_WIDTH * r
        top = H - clearance
        lo, hi = np.full(3, -top), np.full(3, top)
        if rng is None:
            from scipy.stats import qmc

            halton = qmc.Halton(d=3, scramble=False)
            halton.fast_forward(1)

            def draw(m):
                return lo + (hi - lo) * halton.random(m)
        else:
            def draw(m):
                return rng.uniform(lo, hi, (m, 3))
        C = near_level_set(draw, OVERSAMPLING * n, lambda Y: six_pipes_value_gradient(Y, r, k),
                           delta, 8192, 40)
        C = project_to_surface(C, r, k)
        C = C[np.abs(C).max(axis=1) <= top]
        if rng is None:
            return self._mirrored(C[C[:, 0] >= 0.0], n)
        return C[farthest_point_order(C, n, int(rng.integers(len(C))))]

    def _mirrored(self, half: np.ndarray, n: int) -> np.ndarray:
        """n points mirror symmetric about x = 0: a farthest-point order of the candidates
        with x ≥ 0, points closer than MIRROR_SNAP spacings to the plane moved onto it (F is
        even in x, so they stay on F = 0), the rest doubled by x → −x; the order is cut where
        the count reaches n (one point on the plane dropped if it passes n by one)."""
        order = half[farthest_point_order(half, min(n, len(half)), 0)]
        snap = np.abs(order[:, 0]) < MIRROR_SNAP * self.spacing(int(self.n_points))
        total = 2 * np.arange(1, len(order) + 1) - np.cumsum(snap)
        m = int(np.searchsorted(total, n)) + 1
        P, on_plane = order[:m].copy(), snap[:m]
        P[on_plane, 0] = 0.0
        r, _, k = self._geometry()
        P[on_plane] = project_to_surface(P[on_plane], r, k)   # ∂F/∂x = 0 on x = 0: stays
        P[on_plane, 0] = 0.0
        if 2 * m - on_plane.sum() == n + 1:
            keep = np.ones(m, dtype=bool)
            keep[np.flatnonzero(on_plane)[-1]] = False
            P, on_plane = P[keep], on_plane[keep]
        out = np.vstack([P, P[~on_plane] * np.array([-1.0, 1.0, 1.0])])
        if len(out) != n:
            raise RuntimeError(f"six_pipes: the mirrored selection gave {len(out)} points, "
                               f"not {n}")
        return out

    def load(self, rng: np.random.Generator) -> PointCloud:
        """Sample the surface, its end circles and the markers; randomness only from rng."""
        return load_pipes(self, rng)

    def _exact(self):
        r, H, _ = self._geometry()
        return {"area": self._area(), "euler_characteristic": -4, "genus": 0,
                "n_boundary_curves": 6, "pipe_radius": r, "pipe_length": 2 * H}
