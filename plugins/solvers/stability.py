"""Is an equilibrium stable? The negative eigenvalues of the constrained tangent, checked.

An equilibrium of Π_ρ is a minimum (stable) when the constrained tangent K_T + ρCᵀC is
positive definite. A direct factorisation gives the count of negative eigenvalues by
Sylvester's law of inertia (:attr:`.linear_backends.Factorization.negative_pivots`), but
only up to round-off; :func:`confirmed_negative_count` checks a positive count with
shift-invert Lanczos (:func:`negative_modes`) on the same factorisation. A backend without
inertia (count -1, the CG backends) is never taken for stable: Lanczos looks for negative
eigenvalues, and when it finds none, the inertia of a direct factorisation decides.
"""
from __future__ import annotations

import numpy as np


def negative_modes(system, count: int, tol: float = 1e-8, max_iter: int = 100,
                   return_nearest: bool = False):
    """(eigenvalues, vectors) of the factorised K_T + ρCᵀC
    (:class:`.augmented_lagrangian.ConstrainedSystem`) that are negative, most negative first, by shift-invert Lanczos (scipy ``eigsh``, σ = 0)
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
    """Negative eigenvalues of the factorised tangent, checked (always ≥ 0): the pivot signs
    of the unpivoted factorisation give the inertia only up to round-off, and K_T + ρCᵀC
    with a large ρ and weakly held ghost DOFs is ill-conditioned enough for a tiny positive
    pivot to come out negative. When the pivots report n > 0 negative values, Lanczos
    (:func:`negative_modes`, up to ``max_modes``) looks for them; if it finds some, their
    count is returned (n itself when all ``max_modes`` are negative). If it finds none, a
    negative eigenvalue may still hide beyond a cluster of tiny positive (ghost) ones, where
    Lanczos converges slowly (the pull-out cylinder: λ = −0.63 behind ~2e-5 ghost modes):
    Sylvester's law of inertia decides, with the pivots of K_ρ + τI, τ ten times the largest
    of the eigenvalues nearest 0 that Lanczos saw first (a shift that lifts round-off-level
    eigenvalues clear of 0 and keeps a real instability negative). The pivot count is kept
    if ARPACK fails.

    A backend without inertia (``negative_pivots`` = -1) goes the same way with n unknown:
    the negative values Lanczos finds (up to ``max_modes``) are counted, and if it finds
    none (or ARPACK fails) the inertia of a direct factorisation of K_ρ + τI (τ as above, 0
    after an ARPACK failure) decides."""
    count = getattr(system, "negative_pivots", -1)
    if count == 0:
        return 0
    known = count > 0
    wanted = min(count, max_modes) if known else max_modes
    near = np.zeros(0)
    try:
        vals, _, near = negative_modes(system, wanted, return_nearest=True)
        if vals.size:
            return count if known and vals.size >= wanted else int(vals.size)
    except Exception:   # ARPACK failure: keep the pivot count
        if known:
            return count
    from scipy.sparse import identity

    from .linear_backends import factorize, inertia_backend

    tau = 10.0 * float(np.abs(near).max()) if near.size else 0.0
    shifted = factorize((system.matrix + tau * identity(system.matrix.shape[0])).tocsr(),
                        inertia_backend(getattr(system, "backend", "superlu")))
    return int(shifted.negative_pivots)
