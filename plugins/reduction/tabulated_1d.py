"""A one-dimensional reduced Lagrangian tabulated once, and its α = 0 variational integrator
compiled with numba, for long runs (thesis §5.3 with Appendix C; the 10⁴-period energy
check of ``rom_pendulum``).

The reduced mass M̃(q) and potential Ṽ(q) of a :class:`~.reduced_lagrangian.
ReducedLagrangian` with d = 1 are evaluated (through the LME basis) at ``n`` equally spaced
q on [q_lo, q_hi] and interpolated by cubic splines; the integrator uses the splines and
their exact derivatives, i.e. the Lagrangian ½ M̃_h(q) q̇² − Ṽ_h(q) of smooth functions that
agree with the LME ones to O(h⁴) (the largest deviation at the interval mid-points is
reported as ``table_error``). The α = 0 step solves

    M̃(q_k) v − (Δt/2) M̃′(q_k) v² − Δt F(q_k) − p_k = 0   (F = −Ṽ′)

for v by Newton from the explicit guess, then q_{k+1} = q_k + Δt v, p_{k+1} = M̃(q_k) v.
"""
from __future__ import annotations

import numba
import numpy as np
from scipy.interpolate import CubicSpline


class Table1D:
    """Cubic splines of M̃ and Ṽ over [q_lo, q_hi] (module doc)."""

    def __init__(self, terms, q_lo: float, q_hi: float, n: int = 2049):
        q = np.linspace(q_lo, q_hi, n)
        vals = [terms([x]) for x in q]
        self.q = q
        self.mass = CubicSpline(q, [t.mass[0, 0] for t in vals])
        self.potential = CubicSpline(q, [t.potential for t in vals])
        mid = 0.5 * (q[1:] + q[:-1])
        sample = mid[:: max(1, len(mid) // 64)]
        exact = np.array([terms([x]).mass[0, 0] for x in sample])
        self.table_error = float(np.abs(self.mass(sample) / exact - 1.0).max())

    def arrays(self):
        return (self.q[0], self.q[1] - self.q[0], np.ascontiguousarray(self.mass.c.T),
                np.ascontiguousarray(self.potential.c.T))


@numba.njit(cache=True)
def _eval(q, q0, h, c):
    """(value, derivative) of a cubic spline with uniform breakpoints (coefficients c (n, 4),
    highest power first, as scipy's PPoly)."""
    n = c.shape[0]
    i = int((q - q0) / h)
    if i < 0:
        i = 0
    if i > n - 1:
        i = n - 1
    s = q - (q0 + i * h)
    a, b, cc, d = c[i, 0], c[i, 1], c[i, 2], c[i, 3]
    return ((a * s + b) * s + cc) * s + d, (3.0 * a * s + 2.0 * b) * s + cc


@numba.njit(cache=True)
def _run(q, p, dt, n_steps, save_every, q0, h, cm, cv, q_lo, q_hi, tol, max_newton):
    n_out = n_steps // save_every + 1
    Q = np.empty(n_out)
    E = np.empty(n_out)
    m, _ = _eval(q, q0, h, cm)
    V, _ = _eval(q, q0, h, cv)
    Q[0], E[0] = q, 0.5 * p * p / m + V
    k_out = 1
    for k in range(1, n_steps + 1):
        m, dm = _eval(q, q0, h, cm)
        _, dV = _eval(q, q0, h, cv)
        v = (p - dt * dV) / m
        ok = False
        for it in range(max_newton):
            R = m * v - 0.5 * dt * dm * v * v + dt * dV - p
            J = m - dt * dm * v
            dv = -R / J
            v += dv
            if abs(dv) <= tol * (1.0 + abs(v)):
                ok = True
                break
        if not ok:
            return Q[:k_out], E[:k_out], k - 1
        p = m * v
        q = q + dt * v
        if q < q_lo or q > q_hi:
            return Q[:k_out], E[:k_out], -k
        if k % save_every == 0:
            m1, _ = _eval(q, q0, h, cm)
            V1, _ = _eval(q, q0, h, cv)
            Q[k_out], E[k_out] = q, 0.5 * p * p / m1 + V1
            k_out += 1
    return Q[:k_out], E[:k_out], n_steps


def integrate_table(table: Table1D, q0: float, v0: float, dt: float, n_steps: int,
                    save_every: int = 1, tol: float = 1e-13, max_newton: int = 30):
    """(times, q, energy, steps done): the α = 0 integrator on the table from (q₀, q̇₀).
    InputError when the trajectory leaves the table's interval (the manifold's sampled
    region) or Newton fails, with the states reached."""
    from pointatlas.errors import InputError

    qa, h, cm, cv = table.arrays()
    m0 = float(table.mass(q0))
    Q, E, done = _run(float(q0), m0 * float(v0), float(dt), int(n_steps), int(save_every),
                      qa, h, cm, cv, float(table.q[0]), float(table.q[-1]), tol, max_newton)
    t = np.arange(len(Q)) * dt * save_every
    if done < 0:
        raise InputError(f"the reduced trajectory left the slow manifold's sampled region "
                         f"[{table.q[0]:.4g}, {table.q[-1]:.4g}] at step {-done} (t = "
                         f"{-done * dt:.6g}); start inside it, lower the energy, or sample a "
                         f"wider region.")
    if done < n_steps:
        raise InputError(f"Newton did not solve the reduced step {done + 1} (t = "
                         f"{(done + 1) * dt:.6g}); lower the time step.")
    return t, Q, E, done
