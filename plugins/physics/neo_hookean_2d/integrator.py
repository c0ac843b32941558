"""Explicit central-difference (velocity-Verlet) time integration of M ẍ = f_ext − f_int(x).

One step of size Δt (the explicit midpoint rule of Millán 2012 §5.2; the variational
integrator of the discrete Lagrangian L_d = Δt [½ (Δx/Δt)ᵀ M (Δx/Δt) − ½ V(x₀) − ½ V(x₁)])::

    x_{n+1} = x_n + Δt v_n + Δt²/2 a_n
    a_{n+1} = M⁻¹ (f_ext − f_int(x_{n+1}))        (0 on the clamped nodes)
    v_{n+1} = v_n + Δt/2 (a_n + a_{n+1})

It is symplectic and second order: the energy error stays bounded, O((ωΔt)²), and does not
drift. It is stable for Δt < Δt_crit = 2 / ω_max with ω_max² the largest eigenvalue of
M_ff⁻¹ K_ff (K the tangent at the start, free DOFs only): :func:`critical_time_step`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from .energy import internal_forces


def critical_time_step(body, mass, x: np.ndarray) -> float:
    """Δt_crit = 2 / ω_max, ω_max² = λ_max(M_ff⁻¹ K_ff(x)) (Lanczos, scipy ``eigsh``); time."""
    from scipy.sparse import diags
    from scipy.sparse.linalg import eigsh

    free = body.free_dofs
    K = body.tangent(x)[free][:, free]
    if mass.kind == "lumped":                # D^-1/2 K D^-1/2: a standard symmetric problem
        d = diags(1.0 / np.sqrt(np.repeat(mass.lumped, 2)[free]))
        A, B = (d @ K @ d).tocsc(), None
    else:
        A, B = K.tocsc(), mass.dof_matrix()[free][:, free].tocsc()
    n = A.shape[0]
    if n <= 12:
        import scipy.linalg as la

        lam = la.eigh(A.toarray(), None if B is None else B.toarray(), eigvals_only=True)[-1]
    else:
        lam = eigsh(A, k=1, M=B, which="LA", tol=1e-6, return_eigenvectors=False,
                    ncv=min(n, 40))[0]
    return 2.0 / np.sqrt(lam) if lam > 0 else np.inf


@njit(cache=True)
def _advance_lumped(x, v, a, f, triangles, G, area, lam, mu, inv_mass, f_ext, dt, n_steps):
    """``n_steps`` velocity-Verlet steps in place with the lumped mass (inv_mass 0 on the
    clamped nodes); returns (steps done, smallest J seen). Stops after a step whose J ≤ 0."""
    n = x.shape[0]
    half_dt2, half_dt = 0.5 * dt * dt, 0.5 * dt
    jmin = np.inf
    for step in range(n_steps):
        for i in range(n):
            for c in range(2):
                x[i, c] += dt * v[i, c] + half_dt2 * a[i, c]
        j = internal_forces(x, triangles, G, area, lam, mu, f)
        if j < jmin:
            jmin = j
        if j <= 0.0:
            return step + 1, jmin
        for i in range(n):
            for c in range(2):
                anew = inv_mass[i] * (f_ext[i, c] - f[i, c])
                v[i, c] += half_dt * (a[i, c] + anew)
                a[i, c] = anew
    return n_steps, jmin


@dataclass(frozen=True)
class Trajectory:
    """Saved states: ``step`` (k,), ``time`` (k,), positions ``x`` and velocities ``v``
    (k, n, 2) and the energies (k,) per unit thickness: ``kinetic``, ``elastic``,
    ``gravity`` (V_g = −f_extᵀ(x − X)); ``critical_dt`` the stability limit at the start."""

    step: np.ndarray
    time: np.ndarray
    x: np.ndarray
    v: np.ndarray
    kinetic: np.ndarray
    elastic: np.ndarray
    gravity: np.ndarray
    critical_dt: float

    @property
    def total(self) -> np.ndarray:
        return self.kinetic + self.elastic + self.gravity


def integrate(body, mass, x0, v0, dt: float, n_steps: int, save_every: int,
              critical_dt: float | None = None, log=None) -> Trajectory:
    """Velocity-Verlet from (x0, v0) (n, 2) for ``n_steps`` steps of ``dt``, saving every
    ``save_every`` steps (and the first and last). The clamped nodes keep their x0
    positions with zero velocity. InputError (one line) if ``dt`` exceeds Δt_crit (computed
    unless given) or a triangle inverts during the motion."""
    from pointatlas.errors import InputError

    if critical_dt is None:
        critical_dt = critical_time_step(body, mass, x0)
    if dt > critical_dt:
        raise InputError(f"physics.dt={dt:g} is above the stability limit of the explicit "
                         f"scheme Δt_crit = 2/ω_max = {critical_dt:.4g} for this mesh and "
                         f"material; use physics.dt <= {0.9 * critical_dt:.3g}.")
    if log is not None:
        log.info("neo_hookean_2d: Δt = %g, Δt_crit = %.4g, %d steps", dt, critical_dt, n_steps)
    x = np.array(x0, float)
    v = np.array(v0, float)
    v[body.clamped] = 0.0
    tri, G, area, lam, mu = body.kernel_arrays()
    f = np.empty_like(x)
    f_ext = np.ascontiguousarray(body.external_forces)
    internal_forces(x, tri, G, area, lam, mu, f)
    a = mass.accelerations(f_ext - f)
    saved = [0] + list(range(save_every, n_steps + 1, save_every))
    if saved[-1] != n_steps:                 # the last state is always saved
        saved.append(n_steps)
    k = len(saved)
    X, V = np.empty((k, *x.shape)), np.empty((k, *x.shape))
    kin, el, grav = np.empty(k), np.empty(k), np.empty(k)
    done = 0
    for s, target in enumerate(saved):
        while done < target:
            if mass.kind == "lumped":
                n, jmin = _advance_lumped(x, v, a, f, tri, G, area, lam, mu, mass.inverse,
                                          f_ext, dt, target - done)
            else:
                n, jmin = _advance_general(x, v, a, f, body, mass, f_ext, dt, target - done)
            done += n
            if jmin <= 0.0:
                raise InputError(f"a triangle inverted (J = {jmin:.3g}) at step {done} "
                                 f"(t = {done * dt:.4g}): the motion is too violent for "
                                 f"physics.dt={dt:g} or the load too large; lower dt or the "
                                 f"initial deformation/velocity.")
        X[s], V[s] = x, v
        kin[s] = mass.kinetic_energy(v)
        el[s] = body.elastic_energy(x)
        grav[s] = body.gravity_energy(x)
    steps = np.asarray(saved)
    return Trajectory(steps, steps * dt, X, V, kin, el, grav, float(critical_dt))


def _advance_general(x, v, a, f, body, mass, f_ext, dt, n_steps):
    """As :func:`_advance_lumped` with any :class:`~.mass.Mass` (a solve per step)."""
    tri, G, area, lam, mu = body.kernel_arrays()
    jmin = np.inf
    anew = np.empty_like(a)
    for step in range(n_steps):
        x += dt * v + (0.5 * dt * dt) * a
        j = internal_forces(x, tri, G, area, lam, mu, f)
        jmin = min(jmin, j)
        if j <= 0.0:
            return step + 1, jmin
        mass.accelerations(f_ext - f, out=anew)
        v += (0.5 * dt) * (a + anew)
        a[:] = anew
    return n_steps, jmin
