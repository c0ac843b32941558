"""A stroke: the swimmer solved at each sample of a periodic sequence of shapes.

Arroyo et al. 2012, SI "Hydrodynamics": at each sample t_k the shape x_k (generating curve,
body frame) moves its surface with the velocity v_k; :func:`.self_propulsion.solve_shape`
gives V_c(t_k), ω(t_k) and the powers W(t_k). Over the stroke (period T = t_K − t_0, the
last sample repeating the first shape):

    X(t) = ∫_0^t V_c dt,   θ(t) = ∫_0^t ω dt,   P̄ = (1/T) ∫_0^T W dt

by the trapezoidal rule on the samples — second order in the sample spacing in general, and
geometrically convergent for uniformly sampled smooth periodic strokes (the periodic
trapezoidal rule). Net displacement X(T), net rotation θ(T)/2π, mean speed Ū = X(T)/T.
Lighthill efficiency (the SI's definition): the power to drag the time-averaged shape at the
mean speed over the mean power, η = F_U Ū² / P̄, F_U the drag of that shape at unit speed
(:func:`drag_per_speed`), for the exterior power and for interior + exterior.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline

from pointatlas.errors import InputError

from .boundary_elements import discretise
from .meridian import Meridian, sample_bspline
from .self_propulsion import ShapeSolution, SingleLayerSolver, solve_shape


@dataclass
class Discretisation:
    """How each shape is discretised (see the plugin's Config)."""

    n_elements: int = 64
    gauss_points: int = 8
    singular_points: int = 16
    element_spacing: str = "uniform"


@dataclass
class StrokeSolution:
    times: np.ndarray
    shapes: list = field(default_factory=list)      # [(Elements, ShapeSolution)]
    position: np.ndarray | None = None
    angle: np.ndarray | None = None
    mean_shape: np.ndarray | None = None
    drag_per_speed: float = float("nan")
    mean_power_out: float = float("nan")
    mean_power_total: float = float("nan")

    @property
    def period(self) -> float:
        return float(self.times[-1] - self.times[0])

    @property
    def mean_speed(self) -> float:
        return float(self.position[-1]) / self.period

    def efficiency(self, power: float) -> float:
        return self.drag_per_speed * self.mean_speed ** 2 / power


def solve_one(nodes, velocity, mu: float, disc: Discretisation, free: bool = True,
              permeation: bool = True) -> tuple:
    """(Elements, ShapeSolution) of one shape (nodes (n, 2)) with nodal surface velocity
    (n, 3) as (v_r, v_z, v_φ), length/time. ``nodes`` may also be a scipy ``BSpline`` of
    (r, z), with ``velocity`` one of (v_r, v_z, v_φ) on the same parameter
    (:func:`.meridian.sample_bspline`, 4 samples per element, at least 257)."""
    if isinstance(nodes, BSpline):
        nodes, velocity = sample_bspline(nodes, velocity, max(257, 4 * disc.n_elements + 1))
    m = Meridian(nodes)
    v = np.asarray(velocity, dtype=np.float64)
    if v.shape != (len(m.nodes), 3):
        raise InputError(f"the surface velocity has shape {v.shape}; give (v_r, v_z, v_φ) at "
                         f"each of the {len(m.nodes)} nodes, shape ({len(m.nodes)}, 3).")
    if not np.isfinite(v).all():
        raise InputError("the surface velocity has non-finite values; give finite values.")
    el = discretise(m, disc.n_elements, disc.gauss_points, disc.element_spacing)
    spline = m.field(v, (-1.0, 1.0, -1.0))
    return el, solve_shape(el, spline, mu, free=free, permeation=permeation)


def drag_per_speed(nodes, mu: float, disc: Discretisation) -> float:
    """Axial force on the fluid (force/(length/time)) of the body ``nodes`` translated along
    +z at unit speed."""
    el = discretise(Meridian(nodes), disc.n_elements, disc.gauss_points, disc.element_spacing)
    S = SingleLayerSolver(el, mu)
    return S.axial_force(S.unit_translation)


def check_stroke(times, shapes, velocities, tol: float) -> tuple:
    """(times (K+1,), shapes (K+1, n, 2), velocities (K+1, n, 3)) as arrays; InputError when
    times do not increase, the sizes disagree, or the last shape is not the first (the stroke
    is not periodic: |x_K − x_0| ≤ tol × body length needed)."""
    t = np.asarray(times, dtype=np.float64)
    X = np.asarray(shapes, dtype=np.float64)
    V = np.asarray(velocities, dtype=np.float64)
    if X.ndim != 3 or X.shape[-1] != 2 or V.shape != X.shape[:-1] + (3,) or t.shape != X.shape[:1]:
        raise InputError(f"a stroke is times (K+1,), shapes (K+1, n, 2) and velocities "
                         f"(K+1, n, 3); got {t.shape}, {X.shape}, {V.shape}. Give one shape "
                         f"and one velocity per time, the same nodes in each.")
    if len(t) < 3:
        raise InputError(f"a stroke needs at least 3 samples (the last repeating the first); "
                         f"got {len(t)}.")
    if not (np.diff(t) > 0).all():
        raise InputError("the stroke's times must increase strictly; sort or fix them.")
    size = float(np.ptp(X[0][:, 1]) or np.ptp(X[0]))
    gap = float(np.abs(X[-1] - X[0]).max())
    if gap > tol * size:
        raise InputError(f"the stroke is not periodic: its last shape differs from its first by "
                         f"{gap:.3g} (more than {tol:g} × the body length {size:.4g}). End the "
                         f"stroke where it began, or raise physics.periodicity_tol.")
    return t, X, V


def _trapezoid_cumulative(t, f):
    return np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(t))])


def swim_stroke(times, shapes, velocities, mu: float, disc: Discretisation, *,
                permeation: bool = True, tol: float = 1e-6, log=None) -> StrokeSolution:
    """The free swimmer over a stroke (module doc); ``log`` gets one line per 10 % done."""
    t, X, V = check_stroke(times, shapes, velocities, tol)
    out = StrokeSolution(times=t)
    K = len(t)
    for k in range(K):
        out.shapes.append(solve_one(X[k], V[k], mu, disc, True, permeation))
        if log is not None and (10 * (k + 1)) // K != (10 * k) // K:
            log.info("stroke: %d of %d shapes solved", k + 1, K)
    s: list[ShapeSolution] = [sol for _, sol in out.shapes]
    out.position = _trapezoid_cumulative(t, np.array([x.translation for x in s]))
    out.angle = _trapezoid_cumulative(t, np.array([x.rotation for x in s]))
    T = out.period
    out.mean_power_out = float(_trapezoid_cumulative(t, np.array([x.power_out for x in s]))[-1]) / T
    out.mean_power_total = float(_trapezoid_cumulative(
        t, np.array([x.power_total for x in s]))[-1]) / T
    w = np.zeros(K)
    w[1:] += 0.5 * np.diff(t)
    w[:-1] += 0.5 * np.diff(t)
    out.mean_shape = np.einsum("k,knd->nd", w / T, X)
    try:
        out.drag_per_speed = drag_per_speed(out.mean_shape, mu, disc)
    except InputError as exc:
        raise InputError(f"the time-averaged shape of the stroke is not a valid body ({exc}); "
                         f"the efficiency needs it. Check that the shapes share one node "
                         f"labelling.") from None
    return out
