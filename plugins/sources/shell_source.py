"""Shared machinery of the shell-benchmark surfaces (plate, Scordelis–Lo roof, hemisphere,
cylinder of the shell obstacle course, thesis L1330–1450, Paper 1 §4).

The shell surfaces have boundaries (free edges, supported edges, symmetry edges), so the
point sets must contain points exactly on every boundary curve: the structured samplings are
grids in surface-area-proportional parameters whose outer grid lines lie on the edges. The
'random' samplings are the same grids jittered (a jittered grid is quasi-uniform and
unstructured, unlike independent uniform points, which cluster): interior points move by up
to ``JITTER`` of a spacing in both parameters, edge points only along their edge, corners stay.

Markers (thesis §3.3, "a lower order of refinement for the patches than for the nodes",
Paper 1 §4.1.3) default to the same scheme one refinement level coarser: spacing 2h, i.e.
about n_points/4 points. ``n_points`` is a target: grids round it to whole rows (the spacing is tuned so the count
is as near n_points as the grid allows, typically within a few per cent).
"""
from __future__ import annotations

import numpy as np

from pointatlas.constraints import Options
from pointatlas.pointcloud import PointCloud, check_distinct

from .surface_source import COMMON_CONSTRAINTS, SurfaceSource, check_rng

#: Maximal jitter of the 'random' samplings, as a fraction of the local grid spacing.
JITTER = 0.3

#: the common settings (n_points and n_markers are targets here: grids round them to whole
#: rows; n_markers None: one refinement level coarser, about n_points/4) and the model, the
#: full surface or a symmetric part
SHELL_CONSTRAINTS = {**COMMON_CONSTRAINTS, "model": [Options(("full", "quarter"))]}


def intervals(length: float, h: float, minimum: int = 1, multiple: int = 1) -> int:
    """Number of equal intervals of size ≈ h on a segment of the given length: a multiple of
    ``multiple`` (so that e.g. the mid-line is a grid line when multiple = 2), ≥ minimum."""
    n = multiple * int(round(length / (h * multiple)))
    return int(max(minimum, multiple, n))


def rectangle_grid(u_range, nu: int, v_range, nv: int, periodic_u: bool = False):
    """Tensor grid on ``u_range × v_range`` with ``nu``, ``nv`` intervals.

    Non-periodic directions include both end lines (points exactly on the edges); a periodic
    ``u`` takes ``nu`` points without repeating the end. Returns ``(u, v, on_u_edge,
    on_v_edge)`` where ``on_u_edge`` flags points on a line u = const of the boundary.
    """
    if periodic_u:
        u1 = u_range[0] + (u_range[1] - u_range[0]) * np.arange(nu) / nu
        on_u1 = np.zeros(nu, dtype=bool)
    else:
        u1 = np.linspace(u_range[0], u_range[1], nu + 1)
        on_u1 = np.zeros(nu + 1, dtype=bool)
        on_u1[[0, -1]] = True
    v1 = np.linspace(v_range[0], v_range[1], nv + 1)
    on_v1 = np.zeros(nv + 1, dtype=bool)
    on_v1[[0, -1]] = True
    U, V = np.meshgrid(u1, v1, indexing="ij")
    EU, EV = np.meshgrid(on_u1, on_v1, indexing="ij")
    return U.ravel(), V.ravel(), EU.ravel(), EV.ravel()


def jitter(values: np.ndarray, step: float, fixed: np.ndarray, rng: np.random.Generator,
           lo: float | None = None, hi: float | None = None) -> np.ndarray:
    """Move non-fixed values by U(−JITTER, JITTER)·step, clipped to ``[lo, hi]``."""
    out = values + np.where(fixed, 0.0, rng.uniform(-JITTER, JITTER, values.shape) * step)
    if lo is not None or hi is not None:
        out = np.clip(out, lo, hi)
    return out


class ShellSource(SurfaceSource):
    """Base of the shell-benchmark sources; not a plugin by itself.

    Subclasses implement ``_check()``, ``_area()`` (area of the modelled part),
    ``_grid(h, rng)`` returning ``(points (n, 3), parameters (n, 2))`` for spacing ``h``
    (``rng`` is None for 'structured', a Generator for 'random') and ``_exact()``.
    """

    model: str

    def _area(self) -> float:  # pragma: no cover - overridden
        raise NotImplementedError

    def _grid(self, h: float, rng):  # pragma: no cover - overridden
        raise NotImplementedError

    def spacing(self, n: int) -> float:
        """Grid spacing h giving about n points (length units).

        Starts from h = sqrt(area / n) and corrects for the extra edge rows by a few
        fixed-point steps h ← h·sqrt(count/n); returns the h whose count is nearest n.
        """
        h = float(np.sqrt(self._area() / n))
        best = (np.inf, h)
        for _ in range(8):
            count = len(self._grid(h, None)[0])
            best = min(best, (abs(count - n), h))
            if count == n:
                break
            h *= float(np.sqrt(count / n))
        return best[1]

    def load(self, rng: np.random.Generator) -> PointCloud:
        """Sample the surface and its markers; all randomness comes from ``rng``."""
        check_rng(rng)
        self._check_common()
        self._check()
        random = self.sampling == "random"
        h = self.spacing(int(self.n_points))
        points, params = self._grid(h, rng if random else None)
        h_markers = 2.0 * h if self.n_markers is None else self.spacing(int(self.n_markers))
        markers, _ = self._grid(h_markers, rng if random else None)
        check_distinct(points, what=f"{self.name} points")
        return PointCloud(points=points, markers=markers, intrinsic_dim=2,
                          exact={**self._exact(), "spacing": h}, parameters=params,
                          name=self.name)
