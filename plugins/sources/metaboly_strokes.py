"""Known axisymmetric strokes of an elongated cell: the ground truth of ``synthetic_metaboly``.

A spheroidal body of half-length ``length``/2 and equatorial radius ``radius`` (µm) with its
radius modulated by Legendre modes of cos θ (θ ∈ [0, π] the spheroid's polar angle, so the
profile stays smooth at the poles: r is odd and z even about each of them):

    r(θ, φ) = α(φ) · radius · sin θ · (1 + A [cos(2πφ) P₂(cos θ) + s · sin(2πφ) P₃(cos θ)]),
    z(θ)    = β(φ) · (length/2) cos θ,

φ ∈ [0, 1) the phase of the stroke. ``travelling_bulge`` (s = 1) moves a bulge along the body
(a closed loop in shape space: non-reciprocal); ``reciprocal`` (s = 0) swells and slims the
same way forward and back (an arc traced twice); ``euglenid_like`` is the travelling bulge with
the modes P₂, P₃ and P₄ at the amplitude that gives a pellicle shear γ_max ≈ 3 on a body of
reduced volume ≈ 0.6 (Arroyo et al., PNAS 2012, Euglenid #3). Each shape is then stretched,
r → α r and z → β z, so that its area and volume stay those of phase 0: the pellicle is
inextensible (area) and the cells' volume nearly constant, so the reduced volume is constant
along the stroke and the body coordinate (area fraction) labels material parallels exactly.
Curves run from the top pole (θ = 0) to the bottom one, (r, z) in µm.
"""
from __future__ import annotations

import numpy as np
from numpy.polynomial import legendre

STROKES = ("travelling_bulge", "reciprocal", "euglenid_like")


def _p(n, x):
    return legendre.legval(x, np.eye(n + 1)[n])


def modulation(theta, phase, kind: str, amplitude: float):
    """The factor 1 + A(…) of the radius (module doc) at angles θ and one phase."""
    c = np.cos(theta)
    a, b = np.cos(2 * np.pi * phase), np.sin(2 * np.pi * phase)
    if kind == "travelling_bulge":
        w = a * _p(2, c) + b * _p(3, c)
    elif kind == "reciprocal":
        w = a * _p(2, c)
    elif kind == "euglenid_like":
        w = a * _p(2, c) + b * _p(3, c) - 0.5 * a * _p(4, c)
    else:
        raise ValueError(f"stroke kind {kind!r}: use one of {STROKES}")
    return 1.0 + amplitude * w


def _volume(r, z):
    return -np.pi * np.sum(0.5 * (r[1:] ** 2 + r[:-1] ** 2) * np.diff(z))


def _area(r, z):
    return 2.0 * np.pi * np.sum(0.5 * (r[1:] + r[:-1]) * np.hypot(np.diff(r), np.diff(z)))


def _stretch(r, z, S0, V0):
    """(α, β) with area(α r, β z) = S0 and volume(α r, β z) = V0. At fixed volume (α²β) the
    area is least for a roundish body and grows towards needles (α → 0) and discs; the
    elongated branch, α below that minimum, is the cells' (solved by bisection)."""
    from scipy.optimize import brentq, minimize_scalar

    V1 = _volume(r, z)
    beta = lambda a: V0 / (a * a * V1)  # noqa: E731
    area = lambda a: _area(a * r, beta(a) * z) - S0  # noqa: E731
    a_min = minimize_scalar(area, bounds=(0.05, 20.0), method="bounded").x
    if area(a_min) > 0:
        raise ValueError("no stretch of this shape has the area and volume of phase 0 "
                         "(too round at this amplitude); lower the amplitude.")
    a = brentq(area, 0.05, a_min, xtol=1e-14)
    return a, beta(a)


def stroke_shape(phase: float, kind: str = "travelling_bulge", length: float = 50.0,
                 radius: float = 8.0, amplitude: float = 0.4, n_nodes: int = 401):
    """Generating curve (n_nodes, 2) as (r, z) in µm at ``phase`` (module doc)."""
    th = np.linspace(0.0, np.pi, n_nodes)
    z = 0.5 * length * np.cos(th)
    r0 = radius * np.sin(th) * modulation(th, 0.0, kind, amplitude)
    r = radius * np.sin(th) * modulation(th, phase, kind, amplitude)
    a, b = _stretch(r, z, _area(r0, z), _volume(r0, z))
    r, z = a * r, b * z
    r[[0, -1]] = 0.0
    return np.column_stack([r, z])
