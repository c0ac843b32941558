"""The generating curve (meridian) of a body of revolution: checked, splined, oriented.

Nodes (r, z) run from the axis to the axis, r > 0 between. The curve is traversed so that
n = (−z′, r′)/|x′| (the SI's outer normal, Arroyo et al. 2012, Eq. S3) points out of the
body: from the top pole down to the bottom one, i.e. the enclosed volume
V = −π ∫ r² dz > 0. Geometry and nodal fields are interpolated by periodic cubic splines of
the closed cross-section (the curve followed by its mirror image r → −r), parametrised by
the chord-length fraction t ∈ [0, 1] on the physical half; the mirror makes r odd and z even
about each pole, as a smooth body of revolution requires, so the splines are exact to
O(h⁴) up to the poles.
"""
from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from pointatlas.errors import InputError

#: fewest nodes of a generating curve (a cubic spline and one element per node interval)
MIN_NODES = 5
#: |r| at an end node, relative to the curve's length, that still counts as on the axis
AXIS_TOL = 1e-6


def _cross(o, p, q):
    """z-component of (p − o) × (q − o), broadcast over leading axes."""
    return ((p[..., 0] - o[..., 0]) * (q[..., 1] - o[..., 1])
            - (p[..., 1] - o[..., 1]) * (q[..., 0] - o[..., 0]))


def _segments_cross(P: np.ndarray, block_entries: int = 1 << 21) -> tuple[int, int] | None:
    """First pair (i, j), j > i + 1, of polyline segments that intersect properly, or None
    (lexicographic in (i, j)); all pairs of a block of rows at once, blocks of at most
    ``block_entries`` pairs."""
    A, B = P[:-1], P[1:]
    n = len(A)
    rows = max(1, block_entries // max(n, 1))
    j = np.arange(n)
    for i0 in range(0, max(n - 2, 0), rows):
        i = np.arange(i0, min(i0 + rows, n - 2))
        a, b = A[i][:, None], B[i][:, None]
        c, d = A[None], B[None]
        hit = ((_cross(c, d, a) * _cross(c, d, b) < 0) & (_cross(a, b, c) * _cross(a, b, d) < 0)
               & (j[None] >= i[:, None] + 2))
        if hit.any():
            k = int(np.argmax(hit.ravel()))
            return int(i[k // n]), int(k % n)
    return None


def check_meridian(nodes) -> np.ndarray:
    """The nodes (n, 2) as (r, z), float, with the end radii set to 0; InputError naming the
    problem and the fix otherwise (too few nodes, not on the axis at both ends, crossing the
    axis or itself, repeated nodes, traversed with the normal pointing inward)."""
    P = np.array(nodes, dtype=np.float64, copy=True)
    if P.ndim != 2 or P.shape[1] != 2:
        raise InputError(f"a generating curve is an (n, 2) array of (r, z) nodes; got shape "
                         f"{P.shape}. Give one row (r, z) per node.")
    if len(P) < MIN_NODES:
        raise InputError(f"the generating curve has {len(P)} nodes; the boundary elements "
                         f"need at least {MIN_NODES} (axis to axis). Give more nodes.")
    if not np.isfinite(P).all():
        raise InputError("the generating curve has non-finite coordinates; give finite "
                         "(r, z) values.")
    seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
    L = seg.sum()
    if (seg <= 1e-12 * L).any():
        k = int(np.argmax(seg <= 1e-12 * L))
        raise InputError(f"nodes {k} and {k + 1} of the generating curve coincide; remove "
                         f"repeated nodes.")
    for end, k in (("first", 0), ("last", -1)):
        if abs(P[k, 0]) > AXIS_TOL * L:
            raise InputError(f"the generating curve does not {'start' if k == 0 else 'end'} on "
                             f"the axis: its {end} node has r = {P[k, 0]:.6g} (needs |r| ≤ "
                             f"{AXIS_TOL:g} × length). Run the curve from pole to pole.")
    P[0, 0] = P[-1, 0] = 0.0
    if (P[1:-1, 0] <= 0).any():
        k = int(np.argmax(P[1:-1, 0] <= 0)) + 1
        raise InputError(f"the generating curve reaches or crosses the axis at node {k} "
                         f"(r = {P[k, 0]:.6g}); a body of revolution meets the axis only at "
                         f"its two poles. Split it into separate bodies or fix the node.")
    hit = _segments_cross(P)
    if hit is not None:
        raise InputError(f"the generating curve crosses itself (segments {hit[0]} and "
                         f"{hit[1]}); give a simple curve.")
    volume = -np.pi * np.sum(0.5 * (P[1:, 0] ** 2 + P[:-1, 0] ** 2) * np.diff(P[:, 1]))
    if volume <= 0:
        raise InputError("the generating curve runs from the bottom pole to the top one, so "
                         "its normal (−z′, r′) would point into the body; reverse the node "
                         "order (top pole first).")
    return P


def chord_parameter(P: np.ndarray) -> np.ndarray:
    """Chord-length fraction t ∈ [0, 1] of the nodes."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
    return s / s[-1]


def mirrored_spline(t: np.ndarray, values: np.ndarray, parity) -> CubicSpline:
    """A periodic cubic spline on t ∈ [0, 2) of ``values`` (n, k) on t ∈ [0, 1] continued by
    the mirror image t → 2 − t with the sign ``parity`` (k,) (−1: odd about the poles)."""
    parity = np.asarray(parity, dtype=np.float64)
    tt = np.concatenate([t, 2.0 - t[-2::-1]])
    vv = np.concatenate([values, parity * values[-2::-1]])
    vv[-1] = vv[0]
    return CubicSpline(tt, vv, bc_type="periodic", axis=0)


class Meridian:
    """A checked generating curve and its splines: ``point(t)``, ``tangent(t)`` (dx/dt),
    ``normal(t)`` (unit, outward), ``field(values, parity)`` for nodal fields."""

    def __init__(self, nodes):
        self.nodes = check_meridian(nodes)
        self.t_nodes = chord_parameter(self.nodes)
        self._x = mirrored_spline(self.t_nodes, self.nodes, (-1.0, 1.0))
        self._dx = self._x.derivative()

    def point(self, t) -> np.ndarray:
        return self._x(t)

    def tangent(self, t) -> np.ndarray:
        return self._dx(t)

    def normal(self, t) -> np.ndarray:
        d = self._dx(t)
        return np.stack([-d[..., 1], d[..., 0]], axis=-1) / np.linalg.norm(d, axis=-1)[..., None]

    def field(self, values, parity) -> CubicSpline:
        """Spline of nodal values (n, k) on this curve's parameter (parity as in
        :func:`mirrored_spline`)."""
        values = np.asarray(values, dtype=np.float64)
        if values.shape[0] != len(self.nodes):
            raise InputError(f"{values.shape[0]} nodal values for a generating curve of "
                             f"{len(self.nodes)} nodes; give one per node.")
        return mirrored_spline(self.t_nodes, values, parity)


def sample_bspline(curve, velocity=None, n: int = 257):
    """(nodes (n, 2), velocities (n, 3) or None) of a generating curve given as a scipy
    ``BSpline`` of (r, z) (and its velocity as a ``BSpline`` of (v_r, v_z, v_φ) on the same
    parameter), sampled at n parameter values uniform over the curve's base interval."""
    k = curve.k
    lo, hi = curve.t[k], curve.t[-k - 1]
    u = np.linspace(lo, hi, n)
    nodes = np.asarray(curve(u), dtype=np.float64)
    if velocity is None:
        return nodes, None
    return nodes, np.asarray(velocity(u), dtype=np.float64)

