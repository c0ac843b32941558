"""Branch switching at simple bifurcation points of an equilibrium path.

A symmetric structure loaded along a path of symmetric states (the connected pipes under an
imposed displacement, thesis L2557, Paper 2 §5.6) reaches bifurcation points where the
constrained tangent K_T + ρCᵀC loses positive definiteness while λ keeps increasing: the
primary path goes on, but unstable, and an arc-length method follows it. At a simple
bifurcation the critical eigenvector φ (K_T φ = 0 on the constraint space) is orthogonal to
the load, φᵀF = 0, so the path tangent has no component along it; at a limit point the
tangent *is* φ (Riks 1984, "Bifurcation and stability, a numerical approach", in Innovative
Methods for Nonlinear Problems; Wriggers & Simo 1990, Commun. Appl. Numer. Methods 6:303).
Hence the test used here: an increment whose count of negative pivots grew while λ kept
growing, and whose step ΔU is not aligned with the new unstable mode, has crossed a
bifurcation (along a regular path the sign change of det K_T without a turn of λ marks one).

The switch is the eigenvector injection of Wagner & Wriggers (1988, "A simple method for
the calculation of postcritical branches", Eng. Comput. 5:103–109): the next arc-length
increment starts from the predictor ΔU = Δs φ/|φ| (Δλ = 0) instead of the path tangent;
the corrector on the cylinder |ΔU| = Δs then converges to the secondary branch, which
crosses that cylinder near the predictor, and the continuation goes on along it.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from .stability import confirmed_negative_count, negative_modes


def bifurcation_mode(system, step: np.ndarray, mask: np.ndarray, max_cosine: float = 0.95,
                     log=None) -> Optional[np.ndarray]:
    """The direction to inject at a bifurcation just crossed by ``step`` (the last
    increment's ΔU, along which λ kept growing), or None.

    φ is the eigenvector of the most negative eigenvalue nearest 0. If |cos(φ, ΔU)| in the
    masked metric (``mask``: the problem's ``arc_mask``, :mod:`.equilibrium_problem`) is at
    least ``max_cosine`` the unstable mode is the path direction itself (a limit point seen from
    its far side) and None is returned. Otherwise the part of φ orthogonal to ΔU is injected
    (for a symmetric bifurcation φ ⊥ ΔU already; an imperfect or asymmetric one mixes them),
    normalised to unit masked length with its largest entry positive (a reproducible choice
    of the two branches)."""
    count = getattr(system, "negative_pivots", -1)
    if count < 0:   # a backend without inertia: the count Lanczos confirms
        count = confirmed_negative_count(system)
    if count <= 0:
        return None
    vals, vecs = negative_modes(system, count)
    if vals.size == 0:
        return None
    phi = vecs[:, 0]
    cosine = mode_cosine(phi, step, mask)
    if log is not None:
        log.info("  critical mode: eigenvalue %.4g, |cos(φ, ΔU)| = %.3f", vals[0], cosine)
    if cosine >= max_cosine:
        return None
    t = mask * step
    phi = phi - (float(phi @ t) / float(step @ t)) * step
    phi = phi / float(np.sqrt(phi @ (mask * phi)))
    return phi if phi[np.argmax(np.abs(phi))] > 0 else -phi


def mode_cosine(phi: np.ndarray, step: np.ndarray, mask: np.ndarray) -> float:
    """|cos(φ, ΔU)| in the masked metric (dimensionless)."""
    a = float(np.sqrt(phi @ (mask * phi)) * np.sqrt(step @ (mask * step)))
    return abs(float(phi @ (mask * step))) / a if a > 0 else 0.0
