"""Open connected pipes: a ladder of pipes with four open ends (thesis L2557–2566, §5.6).

The nonlinear thin-shell example "connected pipes" of Paper 1 §5.6 is a shell of genus ≥ 2
whose bottom pipe ends are clamped and whose top pipe ends are displaced; lateral dimension
6.2, thickness 0.03. The thesis gives no further geometry; this source builds a smooth
stand-in: two vertical pipes of radius r with axes x = ±a, y = 0, joined by three horizontal
rungs along x at z = −b, 0, +b, cut to |z| ≤ H. Lateral size 2(a + r) = 6.2 for the defaults
(a = 2.65, r = 0.45, H = 3, b = 1.8, blend k = 0.45). The blend sets the fillet curvature:
max |κ| ≈ 2.8/k, 6.2 for the defaults (1/r = 2.2 on the pipes; area·κ²_max ≈ 2700, h·κ_max
≈ 0.95 at 3000 points); r = 0.6 would force k ≤ 0.3 (b ≥ 2(r + k)) and |κ| = 9.2. Two
independent cycles: the closed version has genus 2; the four ends z = ±H are open (four
boundary circles), so χ = 2 − 2g − 4 = −6.

Implicit surface F(x) = smin(d₋, d₊, q₋b, q₀, q_b) − r = 0 with
    d± = sqrt((x ∓ a)² + y²)                   (distance to a vertical axis),
    q_c = sqrt(y² + (z − c)² + ψ(|x|)),  ψ(t) = max(t − a + k, 0)³ / k   (rung at z = c),
and the C² cubic smooth minimum smin(u, v) = min(u, v) − k h³/6, h = max(k − |u − v|, 0)/k,
applied left to right (k = ``blend``). The rungs fade out (ψ > 0) inside the vertical pipes,
a blend radius k before their axes, so they meet the pipes in a smooth fillet without
grazing the outer wall. Junction regions are disjoint boxes |z − c| ≤ r + k, a − r − k ≤ |x|
(checked by the configuration rules), outside which F is the distance to one cylinder
minus r: the pipe ends are plain cylinders on a length H − b − r − k ≥ r/4.

Area: A = 2·2πr·2H + 3·2πr·2a + 6 J(r, k). The junction excess J (area in a junction box
minus the plain cylinders it replaces) scales as r² j(k/r); j is computed once per k/r by
marching cubes (pyvista's contour) of the local junction function on grids of spacing r/24
and r/48 aligned with the box faces, vertices projected onto F = 0 by Newton steps, then
Richardson-extrapolated (O(g²) mesh error), :func:`junction_excess`. For the defaults
j(1) = −8.343548 and A = 70.444440: the extrapolations from r/48 & r/64, r/64 & r/96 and
r/48 & r/96 lie within 3e-5 of j (< 1e-6 relative in A); a marching-cubes mesh of the whole
surface (grid 0.06 & 0.03, Richardson) gives 70.44522 (+1.1e-5 relative, its own error).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar, Optional

import numpy as np

from pointatlas.pointcloud import PointCloud, check_distinct
from pointatlas.stores_config import stores_config

from .farthest_point import farthest_point_order
from .level_set import near_level_set, project_to_level_set
from .shell_source import JITTER
from .surface_source import COMMON_CONSTRAINTS, POSITIVE, SurfaceSource, check_rng, require

#: Candidates per output point for the farthest-point selection (6 left candidate holes that
#: the boundary detection occasionally took for edges, random sampling at 2500 points).
OVERSAMPLING = 12
#: Half-width of the candidate shell around F = 0, as a fraction of the pipe radius.
SHELL_HALF_WIDTH = 0.02
#: Spacing of the boundary circles relative to h = sqrt(area / n_points): the median
#: nearest-neighbour distance of a farthest-point set is ≈ 0.83 h, so the rings match it.
RING_SPACING = 0.85
#: Interior candidates closer than this many ring spacings to an end plane are dropped.
RING_CLEARANCE = 0.8
#: Fewest points on a boundary circle.
MIN_RING_POINTS = 8


# -- the implicit function ---------------------------------------------------------------
def _smin(u, gu, v, gv, k: float):
    """C² cubic smooth minimum of u, v (with gradients gu, gv of shape (n, 3))."""
    h = np.maximum(k - np.abs(u - v), 0.0) / k
    value = np.minimum(u, v) - k * h**3 / 6.0
    du = np.where(u < v, 1.0 - 0.5 * h * h, 0.5 * h * h)
    return value, du[:, None] * gu + (1.0 - du)[:, None] * gv


def _vertical(X, x0: float):
    """Distance to the vertical axis x = x0, y = 0, and its gradient."""
    dx, dy = X[:, 0] - x0, X[:, 1]
    d = np.maximum(np.hypot(dx, dy), 1e-300)
    return d, np.column_stack([dx / d, dy / d, np.zeros_like(d)])


def _rung(X, c: float, a: float, k: float):
    """q_c = sqrt(y² + (z − c)² + ψ(|x|)), ψ(t) = (t − a + k)₊³/k, and its gradient."""
    t = np.maximum(np.abs(X[:, 0]) - (a - k), 0.0)
    q = np.maximum(np.sqrt(X[:, 1] ** 2 + (X[:, 2] - c) ** 2 + t**3 / k), 1e-300)
    gx = np.sign(X[:, 0]) * 1.5 * t * t / k
    return q, np.column_stack([gx, X[:, 1], X[:, 2] - c]) / q[:, None]


def pipes_value_gradient(X: np.ndarray, r: float, a: float, b: float, k: float):
    """F (n,) and ∇F (n, 3) of the module docstring at the rows of X (length units)."""
    X = np.asarray(X, dtype=np.float64)
    F, G = _vertical(X, -a)
    parts = [_vertical(X, a)] + [_rung(X, c, a, k) for c in (-b, 0.0, b)]
    for u, gu in parts:
        F, G = _smin(F, G, u, gu, k)
    return F - r, G


def project_to_surface(X, r, a, b, k, tol: float = 1e-13, max_iter: int = 50):
    """Newton steps x ← x − F ∇F/|∇F|² until |F| ≤ tol·r (along ∇F, which is horizontal
    on the plain cylinders at the ends, so z is kept there)."""
    return project_to_level_set(X, lambda Y: pipes_value_gradient(Y, r, a, b, k), tol * r,
                                max_iter)


def shell_candidates(draw, n: int, r, a, b, k, H: float, half_width: float):
    """Box samples from ``draw(m)`` within |F|/|∇F| < half_width of the surface and
    |z| ≤ H, projected onto F = 0 (n rows; :mod:`.level_set`)."""
    C = near_level_set(draw, n, lambda Y: pipes_value_gradient(Y, r, a, b, k), half_width,
                       8192, 40, accept=lambda Y: np.abs(Y[:, 2]) <= H)
    return project_to_surface(C, r, a, b, k)


# -- area --------------------------------------------------------------------------------
def _junction_mesh_area(kr: float, g: float) -> float:
    """Area of the local junction surface (r = 1, pipe axis x = y = 0, rung along −x at
    z = 0, fading out for x > −k) inside the box x ≥ −L, |z| ≤ Z, L = Z = 1 + k + 0.1,
    from a marching-cubes mesh on a grid of spacing ≈ g whose planes include the box faces."""
    import pyvista as pv

    L = 1.0 + kr + 0.1
    lo = np.array([-L, -1.2, -L])
    hi = np.array([1.2, 1.2, L])
    dims = np.ceil((hi - lo) / g).astype(int) + 1
    spacing = (hi - lo) / (dims - 1)
    grid = pv.ImageData(dimensions=dims, spacing=spacing, origin=lo)

    def local(X):  # one vertical pipe at x = 0 and one rung at z = 0 (offset a = 0)
        d, gd = _vertical(X, 0.0)
        t = np.maximum(X[:, 0] + kr, 0.0)
        q = np.maximum(np.sqrt(X[:, 1] ** 2 + X[:, 2] ** 2 + t**3 / kr), 1e-300)
        gq = np.column_stack([1.5 * t * t / kr, X[:, 1], X[:, 2]]) / q[:, None]
        F, G = _smin(d, gd, q, gq, kr)
        return F - 1.0, G

    grid["F"] = local(np.asarray(grid.points))[0]
    mesh = grid.contour([0.0], scalars="F").triangulate()
    P = np.asarray(mesh.points, dtype=np.float64)
    for _ in range(30):
        F, G = local(P)
        if np.abs(F).max() < 1e-13:
            break
        P -= (F / np.einsum("ij,ij->i", G, G))[:, None] * G
    mesh.points = P
    return float(mesh.area) - 2.0 * np.pi * (2.0 * L + L)


@lru_cache(maxsize=16)
def junction_excess(kr: float, g: float = 1.0 / 24.0) -> float:
    """j(k/r) = J / r²: excess area of one junction over the plain cylinders it replaces
    (r = 1), Richardson-extrapolated from grid spacings g and g/2 (O(g²) mesh error).

    Accuracy: j(1) = −8.343548 from g = 1/24, 1/48; extrapolations from 1/48 & 1/64, 1/64 &
    1/96 and 1/48 & 1/96 lie within 3e-5 of it. Cost about 2 s (cached per k/r).
    """
    coarse = _junction_mesh_area(kr, g)
    fine = _junction_mesh_area(kr, g / 2.0)
    return (4.0 * fine - coarse) / 3.0


def open_pipes_area(r: float, a: float, H: float, k: float) -> float:
    """A = 2·2πr·2H (vertical pipes) + 3·2πr·2a (rungs, axis to axis) + 6 r² j(k/r)."""
    return 4.0 * np.pi * r * (2.0 * H + 3.0 * a) + 6.0 * r * r * junction_excess(k / r)


def load_pipes(source, rng: np.random.Generator) -> PointCloud:
    """The cloud of a pipes source (open_pipes, six_pipes): its ``end_circles`` at ring
    spacing RING_SPACING·h plus ``_interior`` points kept RING_CLEARANCE ring spacings from
    the ends (n_points in all), and n_markers interior markers (default n_points // 4);
    randomness only from rng (``sampling: random``)."""
    check_rng(rng)
    source._check_common()
    source._check()
    n = int(source.n_points)
    random = rng if source.sampling == "random" else None
    h = source.spacing(n)
    rings = source.end_circles(RING_SPACING * h, random)
    inner = source._interior(n - len(rings), random, RING_CLEARANCE * RING_SPACING * h)
    points = np.vstack([inner, rings])
    n_markers = max(4, n // 4) if source.n_markers is None else int(source.n_markers)
    markers = source._interior(n_markers, random, 0.0)
    check_distinct(points, what=f"{source.name} points")
    return PointCloud(points=points, markers=markers, intrinsic_dim=2,
                      exact={**source._exact(), "spacing": h}, parameters=None,
                      name=source.name)


# -- the source --------------------------------------------------------------------------
@stores_config
class OpenPipes(SurfaceSource):
    """Ladder of pipes (two vertical, three rungs), genus 2, four open ends at z = ±H.

    structured: a deterministic Halton sequence in a thin shell around F = 0 (|z| ≤ H),
    projected onto F = 0 by Newton steps, then OVERSAMPLING× thinned by greedy farthest-point
    selection (quasi-uniform, Poisson-disk like), plus the four end circles sampled exactly
    (equally spaced, spacing ≈ RING_SPACING·h, h = sqrt(area/n_points)); interior
    candidates within RING_CLEARANCE ring spacings of the end planes are dropped so the
    ring and the interior meet without crowding.
    random: the same with uniform shell samples from ``rng``, a random first point and, on
    each end circle, a random phase plus a jitter of ±JITTER/2 spacings along the circle.
    Exactly n_points points. Markers: the same interior selection with n_markers points
    (default n_points // 4, one refinement level coarser), no end circles.
    Exact: area (module docstring), χ = −6, genus 2, 4 boundary curves, spacing h.
    """

    @dataclass
    class Config:
        n_points: int = 3000
        sampling: str = "structured"
        pipe_radius: float = 0.45
        half_width: float = 2.65
        half_height: float = 3.0
        rung_offset: float = 1.8
        blend: float = 0.45
        n_markers: Optional[int] = None

        # each > 0; the rules that tie them together are checked in _check: n_points gives at
        # least 8 points per end circle (2πr/h >= 8); pipe_radius r of all pipes; half_width
        # a >= 2r + k (vertical pipes' axes x = ±a, lateral size 2(a+r)); half_height
        # H >= b + r + k + r/4 (the pipes end at z = ±H, plain cylinders there); rung_offset
        # b >= 2(r + k) (rungs at z = −b, 0, b, junction blends kept apart); blend k <= r
        # (smoothing radius of the junction fillets)
        parameter_constraints: ClassVar[dict[str, list]] = {
            **COMMON_CONSTRAINTS, "pipe_radius": POSITIVE, "half_width": POSITIVE,
            "half_height": POSITIVE, "rung_offset": POSITIVE, "blend": POSITIVE}

    description: ClassVar[str] = "Ladder of connected pipes (genus 2) with four open ends."
    name: ClassVar[str] = "open_pipes"

    def _geometry(self):
        return (float(self.pipe_radius), float(self.half_width), float(self.rung_offset),
                float(self.blend))

    def _check(self) -> None:
        r, a, b, k = self._geometry()
        H = float(self.half_height)
        require(k <= r, "blend", self.blend, f"must be in (0, pipe_radius={r}]",
                f"Use a smaller blend, e.g. blend={0.5 * r:g}.")
        require(b >= 2 * (r + k), "rung_offset", self.rung_offset,
                f"must be >= 2·(pipe_radius + blend) = {2 * (r + k):g}, else the rungs or "
                "their fillets touch", "Increase rung_offset, or lower pipe_radius/blend.")
        require(a >= 2 * r + k, "half_width", self.half_width,
                f"must be >= 2·pipe_radius + blend = {2 * r + k:g}, else the vertical pipes "
                "are too close for the radius", "Increase half_width or lower pipe_radius.")
        need = b + r + k + 0.25 * r
        require(H >= need, "half_height", self.half_height,
                f"must be >= rung_offset + 1.25·pipe_radius + blend = {need:g}, so that the "
                "pipe ends are plain cylinders beyond the last fillet",
                f"Increase half_height to {need:g} or lower rung_offset.")
        h = self.spacing(int(self.n_points))
        rings = 2 * np.pi * r / (RING_SPACING * h)
        n_min = int(np.ceil(self._area() / (2 * np.pi * r / (RING_SPACING * MIN_RING_POINTS))
                            ** 2))
        require(rings >= MIN_RING_POINTS - 0.5, "n_points", self.n_points,
                f"gives spacing h = {h:.3g}, too coarse for pipes of radius {r:g} "
                f"(fewer than {MIN_RING_POINTS} points around a pipe)",
                f"Use n_points >= {n_min}.")

    def _area(self) -> float:
        r, a, _, k = self._geometry()
        return open_pipes_area(r, a, float(self.half_height), k)

    def spacing(self, n: int) -> float:
        """h = sqrt(area / n) (length units)."""
        return float(np.sqrt(self._area() / n))

    def implicit_function(self, X: np.ndarray) -> np.ndarray:
        """F at the rows of X (≈ signed distance near the surface, length units)."""
        return pipes_value_gradient(X, *self._geometry())[0]

    def end_circles(self, h: float, rng) -> np.ndarray:
        """Points on the four end circles (x = ±a + r cosθ, y = r sinθ, z = ±H), spacing ≈ h;
        ``rng`` None: θ = 2πj/m, else a random phase per circle and a ±JITTER/2 jitter."""
        r, a, _, _ = self._geometry()
        H = float(self.half_height)
        m = max(MIN_RING_POINTS, int(round(2 * np.pi * r / h)))
        out = []
        for xc in (-a, a):
            for zc in (-H, H):
                theta = 2 * np.pi * np.arange(m) / m
                if rng is not None:
                    theta = theta + 2 * np.pi / m * (rng.uniform() + rng.uniform(
                        -0.5 * JITTER, 0.5 * JITTER, m))
                out.append(np.column_stack([xc + r * np.cos(theta), r * np.sin(theta),
                                            np.full(m, zc)]))
        return np.concatenate(out)

    def _interior(self, n: int, rng, clearance: float) -> np.ndarray:
        """n quasi-uniform points of the surface with |z| ≤ H − clearance (farthest-point
        selection from OVERSAMPLING·n projected shell candidates)."""
        r, a, b, k = self._geometry()
        H = float(self.half_height)
        delta = SHELL_HALF_WIDTH * r
        pad = k / 6.0 + 3.0 * delta  # smin ≥ min − k/6: the fillets bulge by at most k/6
        lo = np.array([-a - r - pad, -r - pad, -H + clearance])
        hi = np.array([a + r + pad, r + pad, H - clearance])
        if rng is None:
            from scipy.stats import qmc

            halton = qmc.Halton(d=3, scramble=False)
            halton.fast_forward(1)  # skip the corner

            def draw(m):
                return lo + (hi - lo) * halton.random(m)
        else:
            def draw(m):
                return rng.uniform(lo, hi, (m, 3))
        C = shell_candidates(draw, OVERSAMPLING * n, r, a, b, k, H - clearance, delta)
        start = 0 if rng is None else int(rng.integers(len(C)))
        return C[farthest_point_order(C, n, start)]

    def load(self, rng: np.random.Generator) -> PointCloud:
        """Sample the surface, its end circles and the markers; randomness only from rng."""
        return load_pipes(self, rng)

    def _exact(self):
        return {"area": self._area(), "euler_characteristic": -6, "genus": 2,
                "n_boundary_curves": 4, "pipe_radius": float(self.pipe_radius),
                "lateral_size": 2.0 * (float(self.half_width) + float(self.pipe_radius))}
