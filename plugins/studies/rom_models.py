"""Reduced models of a full elastic model and their comparison with it (issue 21; thesis §5.4,
Eqs. 11–13; Millán & Arroyo, CMAME 261–262 (2013) 118, §3.5 and §5.4).

* :func:`pca_manifold` — the affine slow manifold of the d leading principal directions.
* :func:`nonlinear_manifold` — an embedding of the landmark snapshots (any embedder) and the LME
  parametrisation X(q) of the full configurations over it.
* :func:`reduced_run` — the reduced trajectory from a full state (x₀, v₀): q₀ the closest point
  (Appendix B), q̇₀ the M-weighted least-squares velocity (DXᵀ M DX) q̇₀ = DXᵀ M v₀ (Eq. 11),
  integrated by the generalised midpoint rule; a step Newton cannot solve, or one that leaves
  the sampled region, ends the run with the states reached.
* :func:`trajectory_distance` — Eq. 13, D = Σ_j |x_j − X(q_j)|_M / Σ_j |x_j|_M over the saved
  times, |y|_M = √(yᵀ M y) (M the lumped mass, so the norm weighs the body by its mass).
* :func:`reconstruction_error` — Eq. 12, e = (1/M) Σ_a |z_a − X(q(z_a))| / |z_a| over test
  configurations z_a.

Units: lengths those of the physics, time its time unit.
"""
from __future__ import annotations

import time as _time
from dataclasses import dataclass

import numpy as np

from pointatlas.errors import InputError


def pca_manifold(X: np.ndarray, d_max: int, stride: int = 1):
    """(mean (D,), components (d_max, D)) of the rows of X (SVD of every ``stride``-th row)."""
    mean = X.mean(axis=0)
    _, _, Vt = np.linalg.svd(X[::stride] - mean, full_matrices=False)
    return mean, Vt[:d_max]


def embedder_options(name: str, d: int, settings) -> dict:
    """Keyword arguments of the embedder ``name`` at dimension d from the study settings."""
    if name == "nlie":
        return {"n_stress_neighbors": settings.nlie_neighbors,
                "alpha": 1.0 if d == 1 else settings.nlie_alpha}
    if name == "isomap":
        return {"n_neighbors": settings.isomap_neighbors}
    return {}


def nonlinear_manifold(ctx, name: str, d: int, X_full, X_landmarks, settings):
    """(SlowManifold, embedding Q (N, d)) of ``name`` at dimension d."""
    from pointatlas_reduction.slow_manifold import SlowManifold

    if d >= len(X_landmarks):
        raise InputError(f"embedding dimension {d} is not below the number of training "
                         f"snapshots {len(X_landmarks)}; lower study.nonlinear_dims or keep "
                         f"more snapshots (a smaller study.decimation).")
    Q = ctx.make("embedder", name, n_components=d,
                 **embedder_options(name, d, settings)).fit_transform(X_landmarks)
    bins = settings.n_bins if d >= 2 else settings.n_bins_1d
    sm = SlowManifold(ctx.plugin("approximant"), bins).fit(X_full, Q)
    return sm, Q


def initial_velocity(J: np.ndarray, mass: np.ndarray, v0: np.ndarray) -> np.ndarray:
    """q̇₀ solving (Jᵀ M J) q̇₀ = Jᵀ M v₀ for J = DX(q₀) (D, d), M = diag(mass) (Eq. 11)."""
    MJ = mass[:, None] * J
    return np.linalg.solve(J.T @ MJ, MJ.T @ v0)


@dataclass
class ReducedRun:
    """The reduced trajectory's full configurations ``X`` (n_saved, D) at ``time``, the
    reduced energy, the time reached, the wall time (s) and why it stopped early (or '')."""

    time: np.ndarray
    q: np.ndarray
    X: np.ndarray
    energy: np.ndarray
    reached: float
    wall: float
    failure: str
    start_distance: float


def reduced_run(manifold, lagrangian, x0, v0, mass, dt: float, n_steps: int,
                save_every: int, alpha: float = 0.0) -> ReducedRun:
    """Integrate the reduced model from the full state (x₀, v₀) (module doc)."""
    from pointatlas_reduction.variational_integrator import StepFailure, integrate

    q0, dist = manifold.project(x0)
    _, J = manifold.evaluate(q0[None], order=1)
    qd0 = initial_velocity(J[0], mass, v0)
    t0 = _time.perf_counter()
    try:
        tr = integrate(lagrangian.terms, q0, qd0, dt, n_steps, alpha=alpha,
                       save_every=save_every)
        t, Q, E, failure = tr.time, tr.q, tr.energy, ""
    except StepFailure as err:
        t, Q, _ = err.states
        E, failure = np.full(len(t), np.nan), str(err)
    wall = _time.perf_counter() - t0
    return ReducedRun(t, Q, manifold.evaluate(Q), E, float(t[-1]), wall, failure, dist)


def mass_norms(Y: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """|y|_M = √(yᵀ diag(mass) y) of each row of Y."""
    return np.sqrt(np.einsum("ij,j,ij->i", Y, mass, Y))


def trajectory_distance(X_full: np.ndarray, X_reduced: np.ndarray, mass: np.ndarray) -> float:
    """Eq. 13 over the common saved times (rows)."""
    n = min(len(X_full), len(X_reduced))
    return float(mass_norms(X_full[:n] - X_reduced[:n], mass).sum()
                 / mass_norms(X_full[:n], mass).sum())


def reconstruction_error(manifold, Z: np.ndarray) -> float:
    """Eq. 12 over the rows of Z (closest-point q(z))."""
    err = [manifold.project(z)[1] / np.linalg.norm(z) for z in Z]
    return float(np.mean(err))


def pca_reconstruction_error(mean, components, Z) -> np.ndarray:
    """Eq. 12 for PCA (thesis Eq. 1) for every d = 1 … len(components), one pass."""
    Y = Z - mean
    C = Y @ components.T                                       # (M, d_max)
    norms2 = np.sum(Y * Y, axis=1)
    resid2 = np.maximum(norms2[:, None] - np.cumsum(C * C, axis=1), 0.0)
    return np.mean(np.sqrt(resid2) / np.linalg.norm(Z, axis=1)[:, None], axis=0)
