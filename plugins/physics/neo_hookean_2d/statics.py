"""Static equilibrium f_int(x) = s f_ext on the free DOFs: Newton with the exact tangent.

Minimises the total potential Π_s(x) = V_el(x) − s f_extᵀ (x − X) over the free DOFs
(clamped nodes at their start positions). Each Newton step solves K_ff δ = r_f with
r = s f_ext − f_int and is scaled by backtracking until Π decreases (Armijo) or the
residual does, and no triangle inverts (Π = +∞ there). When Newton fails at the full load,
the load is ramped: the load factor s advances by an increment that halves on each failure
and doubles back on success.
Converged when ‖r_f‖₂ ≤ ``tol`` ‖f_ext,f‖₂, or when below 10⁻⁴ ‖f_ext,f‖₂ a Newton step no
longer halves the residual (the round-off floor of the internal forces, ~10⁻¹⁶ (λ + 2μ) h
per node, which a small load can put above ``tol`` ‖f_ext‖).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class StaticSolution:
    """Equilibrium positions ``x`` (n, 2), total Newton ``iterations``, load ``increments``
    and the final relative ``residual`` ‖r_f‖ / ‖f_ext,f‖."""

    x: np.ndarray
    iterations: int
    increments: int
    residual: float


def _newton(body, x, f_ext, tol, max_iter):
    """(x, iterations, converged) of Newton from x under the load f_ext (n, 2)."""
    from scipy.sparse.linalg import spsolve

    free = body.free_dofs
    X = body.reference
    scale = np.linalg.norm(f_ext.ravel()[free])
    pot = lambda y: body.elastic_energy(y) - float(np.sum(f_ext * (y - X)))  # noqa: E731
    fint, _ = body.internal_forces(x)
    r = (f_ext - fint).ravel()[free]
    P, previous = pot(x), np.inf
    for it in range(1, max_iter + 1):
        norm = np.linalg.norm(r)
        if norm <= tol * scale or (norm <= 1e-4 * scale and norm > 0.5 * previous):
            return x, it - 1, True            # converged, or stalled at the round-off floor
        previous = norm
        K = body.tangent(x)[free][:, free]
        d = spsolve(K.tocsc(), r)
        slope = -float(r @ d)                 # dΠ/dα at α = 0
        if not np.all(np.isfinite(d)) or slope >= 0:
            d, slope = r / (np.abs(K.diagonal()).max() or 1.0), -float(r @ r) / (
                np.abs(K.diagonal()).max() or 1.0)   # not a descent direction: scaled gradient
        alpha = 1.0
        while alpha > 1e-8:
            y = x.copy()
            y.ravel()[free] += alpha * d
            Py = pot(y)
            if np.isfinite(Py):
                fy, _ = body.internal_forces(y)
                ry = (f_ext - fy).ravel()[free]
                if (Py <= P + 1e-4 * alpha * slope        # Armijo on Π, or (near the solution,
                        or np.linalg.norm(ry) <= (1 - 1e-4 * alpha) * norm):  # where Π rounds
                    break                                 # off) a smaller residual
            alpha *= 0.5
        else:
            return x, it, False
        x, P, r = y, Py, ry
    return x, max_iter, bool(np.linalg.norm(r) <= tol * scale)


def static_equilibrium(body, load: np.ndarray | None = None, x_start: np.ndarray | None = None,
                       tol: float = 1e-10, max_iter: int = 30,
                       min_increment: float = 1e-4) -> StaticSolution:
    """Equilibrium of ``body`` under the nodal ``load`` (n, 2), force / length (default: its
    weight ``body.external_forces``), from ``x_start`` (default: the reference). InputError
    (one line) when the load cannot be ramped to 1 (buckling, or too large a load)."""
    from pointatlas.errors import InputError

    f_ext = body.external_forces if load is None else np.asarray(load, float)
    x = np.array(body.reference if x_start is None else x_start, float)
    if not np.any(f_ext.ravel()[body.free_dofs]):
        return StaticSolution(x, 0, 0, 0.0)
    s, ds, total_it, increments = 0.0, 1.0, 0, 0
    while s < 1.0:
        step = min(ds, 1.0 - s)
        y, it, ok = _newton(body, x, (s + step) * f_ext, tol, max_iter)
        total_it += it
        if ok:
            x, s, increments = y, s + step, increments + 1
            ds = min(1.0, 2.0 * step)
            continue
        ds = 0.5 * step
        if ds < min_increment:
            raise InputError(f"no static equilibrium found beyond {s:.4g} of the load (Newton "
                             f"fails at load factor {s + step:.4g}); the body may buckle or "
                             f"invert: lower the load (physics.initial_load or gravity).")
    fint, _ = body.internal_forces(x)
    res = np.linalg.norm((f_ext - fint).ravel()[body.free_dofs]) / np.linalg.norm(
        f_ext.ravel()[body.free_dofs])
    return StaticSolution(x, total_it, increments, float(res))
