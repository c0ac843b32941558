"""Branch switching at simple bifurcation points of a shell's equilibrium path.

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


def negative_modes(system, count: int, tol: float = 1e-8, max_iter: int = 100,
                   return_nearest: bool = False):
    """(eigenvalues, vectors) of the factorised K_T + ρCᵀC (:class:`.solver.ConstrainedSystem`)
    that are negative, most negative first, by shift-invert Lanczos (scipy ``eigsh``, σ = 0)
    reusing the factorisation: one back-substitution per step. Units: force per length.

    First the ``count`` + 6 eigenvalues nearest 0 (largest |1/λ|; fast, and an instability
    just crossed has its eigenvalue there); if none of them is negative, the most negative
    shifted values 1/λ, i.e. the negative eigenvalues nearest 0 beyond the weakly held
    (ghost) DOFs' cluster of small positive ones. That search converges quickly to an
    isolated negative eigenvalue, but behind a dense cluster of tiny positive ones it may
    not converge in ``max_iter`` steps (then no negative eigenvalue is returned, and
    :func:`confirmed_negative_count` falls back on the inertia). With ``return_nearest`` the
    eigenvalues of the first stage are returned too, as a third item."""
    from scipy.sparse.linalg import ArpackNoConvergence, LinearOperator, eigsh

    A = system.matrix
    n = A.shape[0]
    inverse = LinearOperator(A.shape, matvec=system.inverse, dtype=float)
    # a fixed starting vector: ARPACK's own random one depends on the calls made before in
    # the process, so a resumed path would pick other eigenvector signs than an
    # uninterrupted one
    v0 = np.random.default_rng(0).uniform(0.5, 1.5, n)
    vals, vecs, nearest = np.zeros(0), np.zeros((n, 0)), np.zeros(0)
    for which, k in (("LM", max(count, 1) + 6), ("SA", max(count, 1))):
        k = int(min(k, n - 2))
        if k < 1:
            break
        try:
            vals, vecs = eigsh(A, k=k, sigma=0.0, which=which, OPinv=inverse, tol=tol,
                               maxiter=max_iter, v0=v0)
        except ArpackNoConvergence as exc:
            vals, vecs = exc.eigenvalues, exc.eigenvectors
        if which == "LM":
            nearest = vals
        if np.any(vals < 0):
            break
    order = np.argsort(vals)
    vals, vecs = vals[order], vecs[:, order]
    keep = vals < 0
    if return_nearest:
        return vals[keep], vecs[:, keep], nearest
    return vals[keep], vecs[:, keep]


def confirmed_negative_count(system, max_modes: int = 6) -> int:
    """Negative eigenvalues of the factorised tangent, checked: the pivot signs of the
    unpivoted factorisation give the inertia only up to round-off, and K_T + ρCᵀC with a
    large ρ and weakly held ghost DOFs is ill-conditioned enough for a tiny positive pivot
    to come out negative. When the pivots report n > 0 negative values, Lanczos
    (:func:`negative_modes`, up to ``max_modes``) looks for them; if it finds some, their
    count is returned (n itself when all ``max_modes`` are negative). If it finds none, a
    negative eigenvalue may still hide beyond a cluster of tiny positive (ghost) ones, where
    Lanczos converges slowly (the pull-out cylinder: λ = −0.63 behind ~2e-5 ghost modes):
    Sylvester's law of inertia decides, with the pivots of K_ρ + τI, τ ten times the largest
    of the eigenvalues nearest 0 that Lanczos saw first (a shift that lifts round-off-level eigenvalues clear
    of 0 and keeps a real instability negative). The pivot count is kept if ARPACK fails."""
    count = getattr(system, "negative_pivots", -1)
    if count <= 0:
        return count
    try:
        vals, _, near = negative_modes(system, min(count, max_modes), return_nearest=True)
        if vals.size:
            return count if vals.size >= min(count, max_modes) else int(vals.size)
    except Exception:   # ARPACK failure: keep the pivot count
        return count
    from scipy.sparse import identity

    from .solver import factorize

    tau = 10.0 * float(np.abs(near).max()) if near.size else 0.0
    shifted = factorize((system.matrix + tau * identity(system.matrix.shape[0])).tocsr())
    return int(getattr(shifted, "negative_pivots", count))


def bifurcation_mode(system, step: np.ndarray, mask: np.ndarray, max_cosine: float = 0.95,
                     log=None) -> Optional[np.ndarray]:
    """The direction to inject at a bifurcation just crossed by ``step`` (the last
    increment's ΔU, along which λ kept growing), or None.

    φ is the eigenvector of the most negative eigenvalue nearest 0. If |cos(φ, ΔU)| in the
    masked metric (control points of the surface, :func:`.arc_length.arc_mask`) is at least
    ``max_cosine`` the unstable mode is the path direction itself (a limit point seen from
    its far side) and None is returned. Otherwise the part of φ orthogonal to ΔU is injected
    (for a symmetric bifurcation φ ⊥ ΔU already; an imperfect or asymmetric one mixes them),
    normalised to unit masked length with its largest entry positive (a reproducible choice
    of the two branches)."""
    count = getattr(system, "negative_pivots", -1)
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
