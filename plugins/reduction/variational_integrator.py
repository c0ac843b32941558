"""The generalised midpoint variational integrator on a reduced Lagrangian (thesis §5.3,
Eqs. 8–9, Appendix C; Marsden & West, Acta Numerica 10 (2001) 357).

Discrete Lagrangian L_d(q₀, q₁) = Δt L̃(q_α, v), q_α = (1 − α) q₀ + α q₁, v = (q₁ − q₀)/Δt.
With the discrete momenta p₀ = −D₁L_d(q₀, q₁) and p₁ = D₂L_d(q₀, q₁) a step maps (q_k, p_k)
to (q_{k+1}, p_{k+1}) by solving p_k = −D₁L_d(q_k, q_k + Δt v) for v (Newton). For α = 0
(Appendix C), with M̃, ∂M̃, ∂Ṽ at the known q_k,

    R(v) = M̃ v − (Δt/2) g(v) + Δt ∂Ṽ − p_k = 0,   g_i(v) = vᵀ ∂_i M̃ v,
    ∂R/∂v = M̃ − Δt G(v),   G_im = Σ_l ∂_i M̃_ml v_l,
    p_{k+1} = M̃(q_k) v.

α = ½ (the midpoint rule) is solved by Newton with a finite-difference Jacobian. The
integrator is symplectic and momentum preserving: its energy oscillates without drift. A
step Newton cannot solve (``max_newton`` iterations) is retried with Δt/2 up to
``max_cuts`` times; then :class:`StepFailure` carries the states reached.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pointatlas.errors import PointatlasError
from pointatlas_reduction.slow_manifold import OutsideRegion


class StepFailure(PointatlasError):
    """Newton could not solve a reduced step even after cutting it; ``states`` holds the
    (t, q, p) reached."""

    def __init__(self, message, states):
        super().__init__(message)
        self.states = states


@dataclass
class Trajectory:
    time: np.ndarray
    q: np.ndarray
    p: np.ndarray
    energy: np.ndarray
    newton_iterations: np.ndarray


def _step_alpha0(terms, q, p, dt, tol, max_newton):
    T = terms(q)
    Mt, dM, f = T.mass, T.mass_derivative, T.force
    v = np.linalg.solve(Mt, p + dt * f)                       # the explicit guess
    for it in range(1, max_newton + 1):
        g = np.einsum("j,jlk,l->k", v, dM.transpose(0, 1, 2), v)   # g_k = vᵀ ∂_k M̃ v
        R = Mt @ v - 0.5 * dt * g - dt * f - p
        G = np.einsum("mlk,l->km", dM, v)                     # G_km = Σ_l ∂_k M̃_ml v_l
        dv = np.linalg.solve(Mt - dt * G, -R)
        v += dv
        if np.linalg.norm(dv) <= tol * (1.0 + np.linalg.norm(v)):
            return q + dt * v, Mt @ v, it
    return None


def _dLd(terms, q0, q1, dt, alpha):
    """(D₁L_d, D₂L_d) of the generalised midpoint rule."""
    v = (q1 - q0) / dt
    T = terms((1 - alpha) * q0 + alpha * q1)
    g = np.einsum("j,jlk,l->k", v, T.mass_derivative, v)
    Mv = T.mass @ v
    common = dt * (0.5 * g + T.force)                         # ∂L/∂q_α Δt
    return (1 - alpha) * common - Mv, alpha * common + Mv


def _step_alpha(terms, q, p, dt, alpha, tol, max_newton):
    T = terms(q)
    v = np.linalg.solve(T.mass, p + dt * T.force)
    h = 1e-7
    for it in range(1, max_newton + 1):
        R = -_dLd(terms, q, q + dt * v, dt, alpha)[0] - p
        J = np.empty((len(v), len(v)))
        for j in range(len(v)):
            e = np.zeros_like(v)
            e[j] = h * (1.0 + abs(v[j]))
            J[:, j] = (-_dLd(terms, q, q + dt * (v + e), dt, alpha)[0] - p - R) / e[j]
        dv = np.linalg.solve(J, -R)
        v += dv
        if np.linalg.norm(dv) <= tol * (1.0 + np.linalg.norm(v)):
            q1 = q + dt * v
            return q1, _dLd(terms, q, q1, dt, alpha)[1], it
    return None


def _left(err, t, out_t, out_q, out_p) -> StepFailure:
    return StepFailure(f"the reduced trajectory left the slow manifold's sampled region at "
                       f"t = {t:.6g} ({err}); the {len(out_t)} states reached are kept. "
                       f"Sample a wider region (more or longer training trajectories) or "
                       f"start closer to its centre.",
                       (np.array(out_t), np.array(out_q), np.array(out_p)))


def energy(terms, q, p) -> float:
    """H = ½ pᵀ M̃(q)⁻¹ p + Ṽ(q)."""
    T = terms(q)
    return float(0.5 * p @ np.linalg.solve(T.mass, p) + T.potential)


def integrate(terms, q0, v0, dt: float, n_steps: int, alpha: float = 0.0,
              tol: float = 1e-12, max_newton: int = 25, max_cuts: int = 4,
              save_every: int = 1) -> Trajectory:
    """Integrate from (q₀, q̇₀) for ``n_steps`` steps of ``dt``; ``terms(q)`` returns a
    :class:`~.reduced_lagrangian.ReducedTerms`."""
    q = np.asarray(q0, dtype=np.float64).reshape(-1).copy()
    p = terms(q).mass @ np.asarray(v0, dtype=np.float64).reshape(-1)
    out_t, out_q, out_p, out_e, out_it = [0.0], [q.copy()], [p.copy()], [energy(terms, q, p)], [0]
    t = 0.0
    for k in range(1, n_steps + 1):
        h, done, its = dt, 0.0, 0
        while done < dt - 1e-15 * dt:
            try:
                step = (_step_alpha0(terms, q, p, h, tol, max_newton) if alpha == 0.0 else
                        _step_alpha(terms, q, p, h, alpha, tol, max_newton))
            except OutsideRegion as err:
                raise _left(err, t + done, out_t, out_q, out_p) from None
            if step is None:
                if h < dt / 2 ** max_cuts:
                    states = (np.array(out_t), np.array(out_q), np.array(out_p))
                    raise StepFailure(
                        f"Newton did not solve the reduced step at t = {t + done:.6g} even "
                        f"with Δt/{2 ** max_cuts} (q = {np.round(q, 6).tolist()}); the "
                        f"{len(out_t)} states reached are kept. Lower the time step, or check "
                        f"that the trajectory stays inside the slow manifold's sampled region.",
                        states)
                h /= 2.0
                continue
            q, p, it = step
            done += h
            its += it
        t += dt
        if k % save_every == 0 or k == n_steps:
            try:
                e = energy(terms, q, p)
            except OutsideRegion as err:
                raise _left(err, t, out_t, out_q, out_p) from None
            out_t.append(t)
            out_q.append(q.copy())
            out_p.append(p.copy())
            out_e.append(e)
            out_it.append(its)
    return Trajectory(np.array(out_t), np.array(out_q), np.array(out_p), np.array(out_e),
                      np.array(out_it))
