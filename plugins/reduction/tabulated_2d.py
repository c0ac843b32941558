"""A two-dimensional reduced Lagrangian tabulated once on a uniform tensor grid, and its α = 0
variational integrator compiled with numba, for long runs (thesis Millán 2012 §5.3 with
Appendix C; the two-dimensional counterpart of :mod:`.tabulated_1d`).

L̃(q, q̇) = ½ q̇ᵀ M̃(q) q̇ − Ṽ(q), q ∈ R². The reduced terms (:class:`~.reduced_lagrangian.
ReducedTerms`, through the LME basis) are evaluated once at the nx × ny points of a uniform
grid over the box [lo, hi]; a point the caller flags invalid lies outside the sampled region,
and a cell is usable only if its four corners are valid. Each of Ṽ, M̃₁₁, M̃₁₂, M̃₂₂ is
interpolated per cell by bicubic Hermite interpolation (Fritsch & Carlson's tensor form, e.g.
Press et al., Numerical Recipes §3.6) from its corner values f, the exact ∂f/∂q₁, ∂f/∂q₂ and
the cross derivative ∂²f/∂q₁∂q₂, the mean of the central differences of the exact first
derivatives (d(∂₁f)/dq₂ and d(∂₂f)/dq₁; second-order one-sided at the grid's edges or next to
invalid points). The interpolant is C¹ across cells and agrees with the exact terms to O(h⁴);
the largest relative deviation at up to 64 cell centres is reported as ``table_error``
(M̃ in the Frobenius norm, Ṽ relative to its range over the valid points). Each cell keeps the
16 coefficients of each quantity as a polynomial in (q₁ − q₁ᵢ, q₂ − q₂ⱼ), so value and
gradient are a few Horner steps.

The α = 0 step from (q_k, p_k) solves, by Newton from the explicit guess,

    R(v) = M̃(q_k) v − (Δt/2) g(v) + Δt ∂Ṽ(q_k) − p_k = 0,   g_i(v) = vᵀ ∂_i M̃ v,
    ∂R/∂v = M̃ − Δt G(v),   G_im = Σ_l ∂_i M̃_ml v_l,

then q_{k+1} = q_k + Δt v, p_{k+1} = M̃(q_k) v. A step Newton cannot solve in ``max_newton``
iterations is retried as two half steps, recursively, up to ``max_cuts`` halvings. Units:
those of M̃ and Ṽ; q in the embedding's units, t in those implied by M̃ and Ṽ.
"""
from __future__ import annotations

import math

import numba
import numpy as np

from pointatlas.errors import InputError
from pointatlas_reduction.reduced_lagrangian import ReducedTerms

# p(s, t) = [1 s s² s³] A F Aᵀ [1 t t² t³]ᵀ on the unit square (F: corner data, module doc)
_HERMITE = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [-3, 3, -2, -1], [2, -2, 1, 1]])


def _shift(A, k):
    """B[i] = A[i + k] along axis 0, zero (False) where i + k is off the grid."""
    B = np.zeros_like(A)
    n = A.shape[0]
    if abs(k) < n:
        if k >= 0:
            B[:n - k] = A[k:]
        else:
            B[-k:] = A[:n + k]
    return B


def _derivative(A, ok, h, axis):
    """d A/d q_axis for A (nx, ny, c) on the valid points ok (nx, ny): central differences
    where both neighbours are valid, else second-order (then first-order) one-sided."""
    A, ok = np.moveaxis(A, axis, 0), np.moveaxis(ok, axis, 0)
    a = {k: _shift(A, k) for k in (-2, -1, 1, 2)}
    o = {k: _shift(ok, k) for k in (-2, -1, 1, 2)}
    D = np.zeros_like(A)
    cases = [(o[-1], (A - a[-1]) / h), (o[1], (a[1] - A) / h),
             (o[-1] & o[-2], (3 * A - 4 * a[-1] + a[-2]) / (2 * h)),
             (o[1] & o[2], (-3 * A + 4 * a[1] - a[2]) / (2 * h)),
             (o[-1] & o[1], (a[1] - a[-1]) / (2 * h))]              # increasing priority
    for mask, value in cases:
        D = np.where((mask & ok)[..., None], value, D)
    return np.moveaxis(D, 0, axis)


def _loop_batch(terms):
    """A vectorised terms_batch from a pointwise ``terms(q) -> ReducedTerms``; a point is
    valid when its terms are finite."""
    def batch(Q):
        m = len(Q)
        M, dM = np.empty((m, 2, 2)), np.empty((m, 2, 2, 2))
        V, F = np.empty(m), np.empty((m, 2))
        for i, q in enumerate(Q):
            T = terms(q)
            M[i], dM[i], V[i], F[i] = T.mass, T.mass_derivative, T.potential, T.force
        valid = (np.isfinite(M).all(axis=(1, 2)) & np.isfinite(dM).all(axis=(1, 2, 3))
                 & np.isfinite(V) & np.isfinite(F).all(axis=1))
        return valid, M, dM, V, F
    return batch


class Table2D:
    """Bicubic Hermite tables of Ṽ, M̃₁₁, M̃₁₂, M̃₂₂ on an nx × ny grid over [lo, hi]
    (module doc), from a pointwise ``terms(q) -> ReducedTerms``; see also :meth:`from_batch`.

    Attributes: ``lo``, ``hi``, ``n``, the grid axes ``x`` (nx,) and ``y`` (ny,), ``valid``
    (nx, ny), ``usable`` (nx − 1, ny − 1) cells, ``coefficients`` (nx − 1, ny − 1, 4, 4, 4)
    [cell, quantity, power of Δq₁, power of Δq₂] and ``table_error``.
    """

    def __init__(self, terms, lo, hi, n=(257, 257)):
        self._build(_loop_batch(terms), lo, hi, n)

    @classmethod
    def from_batch(cls, terms_batch, lo, hi, n=(257, 257)) -> "Table2D":
        """The table from ``terms_batch(Q (m, 2)) -> (valid (m,), mass (m, 2, 2),
        mass_derivative (m, 2, 2, 2), potential (m,), force (m, 2))``, all grid points at once."""
        table = cls.__new__(cls)
        table._build(terms_batch, lo, hi, n)
        return table

    def _build(self, batch, lo, hi, n):
        lo, hi = np.asarray(lo, np.float64).reshape(-1), np.asarray(hi, np.float64).reshape(-1)
        n = np.broadcast_to(np.asarray(n, dtype=int), (2,))
        if lo.shape != (2,) or hi.shape != (2,) or not np.all(hi > lo) or np.any(n < 2):
            raise InputError(f"a 2-D table needs lo < hi (two coordinates each) and n ≥ 2 "
                             f"per direction, got lo = {lo.tolist()}, hi = {hi.tolist()}, "
                             f"n = {n.tolist()}; fix the box or the grid size.")
        self.lo, self.hi, self.n = lo, hi, tuple(int(k) for k in n)
        self.x, self.y = np.linspace(lo[0], hi[0], n[0]), np.linspace(lo[1], hi[1], n[1])
        self.h = np.array([self.x[1] - self.x[0], self.y[1] - self.y[0]])
        grid = np.stack(np.meshgrid(self.x, self.y, indexing="ij"), axis=-1).reshape(-1, 2)
        valid, f, d1, d2 = self._quantities(batch, grid)
        shape = (n[0], n[1], 4)
        valid = valid.reshape(n[0], n[1])
        f, d1, d2 = (np.where(valid[..., None], a.reshape(shape), 0.0) for a in (f, d1, d2))
        d12 = 0.5 * (_derivative(d1, valid, self.h[1], 1) + _derivative(d2, valid, self.h[0], 0))
        self.valid = valid
        self.usable = valid[:-1, :-1] & valid[1:, :-1] & valid[:-1, 1:] & valid[1:, 1:]
        if not self.usable.any():
            raise InputError("no cell of the 2-D table has its 4 corners in the sampled "
                             "region; sample a wider region or refine the grid.")
        hx, hy = self.h

        def corners(a, sx, sy):                        # (nx-1, ny-1, 4, 2, 2) of a·sx·sy
            return sx * sy * np.stack([np.stack([a[:-1, :-1], a[:-1, 1:]], -1),
                                       np.stack([a[1:, :-1], a[1:, 1:]], -1)], -2)
        F = np.concatenate([np.concatenate([corners(f, 1, 1), corners(d2, 1, hy)], -1),
                            np.concatenate([corners(d1, hx, 1), corners(d12, hx, hy)], -1)],
                           -2)                         # (nx-1, ny-1, 4, 4, 4)
        C = np.einsum("ai,...ij,bj->...ab", _HERMITE, F, _HERMITE)
        scale = hx ** np.arange(4)[:, None] * hy ** np.arange(4)[None, :]
        C = np.where(self.usable[..., None, None, None], C / scale, np.nan)
        self.coefficients = np.ascontiguousarray(C)
        self.table_error, self.mass_error, self.potential_error = self._error(batch, f)

    @staticmethod
    def _quantities(batch, Q):
        """valid (m,) and the value, ∂/∂q₁, ∂/∂q₂ (m, 4) of Ṽ, M̃₁₁, M̃₁₂, M̃₂₂ at Q."""
        valid, M, dM, V, F = (np.asarray(a, dtype=np.float64) for a in batch(Q))
        m = len(Q)
        M, dM, V, F = (M.reshape(m, 2, 2), dM.reshape(m, 2, 2, 2), V.reshape(m),
                       F.reshape(m, 2))
        Ms, dMs = 0.5 * (M[:, 0, 1] + M[:, 1, 0]), 0.5 * (dM[:, 0, 1] + dM[:, 1, 0])
        f = np.column_stack([V, M[:, 0, 0], Ms, M[:, 1, 1]])
        d = [np.column_stack([-F[:, k], dM[:, 0, 0, k], dMs[:, k], dM[:, 1, 1, k]])
             for k in range(2)]
        valid = valid.reshape(m).astype(bool) & np.isfinite(f).all(1)
        return valid, f, d[0], d[1]

    def _error(self, batch, f):
        """(largest, M̃, Ṽ) relative deviations of the table at up to 64 valid cell centres."""
        cells = np.argwhere(self.usable)
        cells = cells[np.unique(np.linspace(0, len(cells) - 1, min(64, len(cells))).astype(int))]
        centres = self.lo + (cells + 0.5) * self.h
        valid, exact, _, _ = self._quantities(batch, centres)
        tab = self.evaluate(centres)[:, :, 0]
        V = f[..., 0][self.valid]
        span = max(float(V.max() - V.min()), 1e-300)

        def frob(a):
            return np.sqrt(a[:, 1] ** 2 + 2 * a[:, 2] ** 2 + a[:, 3] ** 2)
        e_m = frob(tab - exact)[valid] / frob(exact)[valid]
        e_v = np.abs(tab[:, 0] - exact[:, 0])[valid] / span
        e_m, e_v = (float(e.max()) if len(e) else 0.0 for e in (e_m, e_v))
        return max(e_m, e_v), e_m, e_v

    def arrays(self):
        """The arguments of the numba kernels: (coefficients, usable, x₀, y₀, hx, hy)."""
        return (self.coefficients, self.usable, float(self.lo[0]), float(self.lo[1]),
                float(self.h[0]), float(self.h[1]))

    def evaluate(self, Q) -> np.ndarray:
        """(m, 4, 3): value, ∂/∂q₁, ∂/∂q₂ of Ṽ, M̃₁₁, M̃₁₂, M̃₂₂ at Q (m, 2); NaN outside the
        usable cells."""
        Q = np.ascontiguousarray(np.asarray(Q, dtype=np.float64).reshape(-1, 2))
        return _evaluate_many(Q, *self.arrays())

    def contains(self, q) -> bool:
        """Whether q lies in a usable cell."""
        q = np.asarray(q, dtype=np.float64).reshape(2)
        return _locate(q[0], q[1], *self.arrays()[1:])[0] >= 0

    def terms(self, q) -> ReducedTerms:
        """The tabulated :class:`~.reduced_lagrangian.ReducedTerms` at q (NaN outside)."""
        e = self.evaluate(q)[0]
        M = np.array([[e[1, 0], e[2, 0]], [e[2, 0], e[3, 0]]])
        dM = np.array([[e[1, 1:], e[2, 1:]], [e[2, 1:], e[3, 1:]]])
        return ReducedTerms(mass=M, mass_derivative=dM, potential=float(e[0, 0]),
                            force=-e[0, 1:].copy())


@numba.njit(cache=True)
def _locate(qx, qy, usable, x0, y0, hx, hy):
    """(i, j, Δq₁, Δq₂) of the usable cell holding q, i = −1 if there is none."""
    nx1, ny1 = usable.shape
    sx, sy = (qx - x0) / hx, (qy - y0) / hy
    if not (sx >= 0.0 and sx <= nx1 and sy >= 0.0 and sy <= ny1):
        return -1, 0, 0.0, 0.0
    i, j = min(int(sx), nx1 - 1), min(int(sy), ny1 - 1)
    if not usable[i, j]:
        return -1, 0, 0.0, 0.0
    return i, j, qx - (x0 + i * hx), qy - (y0 + j * hy)


@numba.njit(cache=True)
def _poly(C, i, j, k, dx, dy):
    """(f, ∂f/∂q₁, ∂f/∂q₂) of quantity k of cell (i, j) at the offset (dx, dy)."""
    f, fx, fy = 0.0, 0.0, 0.0
    for a in range(3, -1, -1):
        c = C[i, j, k, a]
        r = ((c[3] * dy + c[2]) * dy + c[1]) * dy + c[0]
        ry = (3.0 * c[3] * dy + 2.0 * c[2]) * dy + c[1]
        fx = fx * dx + f
        f = f * dx + r
        fy = fy * dx + ry
    return f, fx, fy


@numba.njit(cache=True)
def _eval(C, i, j, dx, dy):
    """(Ṽ, ∂₁Ṽ, ∂₂Ṽ, M̃₁₁, M̃₁₂, M̃₂₂, ∂₁M̃₁₁, ∂₂M̃₁₁, ∂₁M̃₁₂, ∂₂M̃₁₂, ∂₁M̃₂₂, ∂₂M̃₂₂)."""
    V, Vx, Vy = _poly(C, i, j, 0, dx, dy)
    a, ax, ay = _poly(C, i, j, 1, dx, dy)
    b, bx, by = _poly(C, i, j, 2, dx, dy)
    c, cx, cy = _poly(C, i, j, 3, dx, dy)
    return V, Vx, Vy, a, b, c, ax, ay, bx, by, cx, cy


@numba.njit(cache=True)
def _evaluate_many(Q, C, usable, x0, y0, hx, hy):
    out = np.full((Q.shape[0], 4, 3), np.nan)
    for m in range(Q.shape[0]):
        i, j, dx, dy = _locate(Q[m, 0], Q[m, 1], usable, x0, y0, hx, hy)
        if i >= 0:
            for k in range(4):
                out[m, k, 0], out[m, k, 1], out[m, k, 2] = _poly(C, i, j, k, dx, dy)
    return out


@numba.njit(cache=True)
def _energy(ev, p1, p2):
    """½ pᵀ M̃⁻¹ p + Ṽ."""
    a, b, c = ev[3], ev[4], ev[5]
    return 0.5 * (c * p1 * p1 - 2.0 * b * p1 * p2 + a * p2 * p2) / (a * c - b * b) + ev[0]


@numba.njit(cache=True)
def _newton(ev, p1, p2, h, tol, max_newton):
    """(converged, v₁, v₂) of the α = 0 step of size h from the terms ev at q_k (module doc)."""
    V, Vx, Vy, a, b, c, ax, ay, bx, by, cx, cy = ev
    r1, r2 = p1 - h * Vx, p2 - h * Vy
    det = a * c - b * b
    v1, v2 = (c * r1 - b * r2) / det, (a * r2 - b * r1) / det      # the explicit guess
    for it in range(max_newton):
        gx = ax * v1 * v1 + 2.0 * bx * v1 * v2 + cx * v2 * v2
        gy = ay * v1 * v1 + 2.0 * by * v1 * v2 + cy * v2 * v2
        R1 = a * v1 + b * v2 - 0.5 * h * gx + h * Vx - p1
        R2 = b * v1 + c * v2 - 0.5 * h * gy + h * Vy - p2
        J11, J12 = a - h * (ax * v1 + bx * v2), b - h * (bx * v1 + cx * v2)
        J21, J22 = b - h * (ay * v1 + by * v2), c - h * (by * v1 + cy * v2)
        dj = J11 * J22 - J12 * J21
        d1, d2 = (J12 * R2 - J22 * R1) / dj, (J21 * R1 - J11 * R2) / dj
        v1 += d1
        v2 += d2
        if not (math.isfinite(v1) and math.isfinite(v2)):
            return False, v1, v2
        if math.sqrt(d1 * d1 + d2 * d2) <= tol * (1.0 + math.sqrt(v1 * v1 + v2 * v2)):
            return True, v1, v2
    return False, v1, v2


@numba.njit(cache=True)
def _run(q1, q2, p1, p2, dt, n_steps, save_every, C, usable, x0, y0, hx, hy, tol,
         max_newton, max_cuts):
    """The integration loop; status 0 done, 1 left the usable cells, 2 Newton failed (at
    step k, time tf, position (f1, f2)). Saves every ``save_every`` steps, the last one, and
    on failure the last complete step."""
    n_out = n_steps // save_every + 2
    T, Q, P, E = np.empty(n_out), np.empty((n_out, 2)), np.empty((n_out, 2)), np.empty(n_out)
    i, j, dx, dy = _locate(q1, q2, usable, x0, y0, hx, hy)
    ev = _eval(C, i, j, dx, dy)
    T[0], Q[0, 0], Q[0, 1], P[0, 0], P[0, 1] = 0.0, q1, q2, p1, p2
    E[0] = _energy(ev, p1, p2)
    n, last = 1, 0
    status, k_fail, tf, f1, f2 = 0, 0, 0.0, 0.0, 0.0
    unit = 1 << max_cuts                       # a step in units of the smallest cut
    for k in range(1, n_steps + 1):
        s1, s2, sp1, sp2, sev = q1, q2, p1, p2, ev
        pos, level = 0, 0
        while pos < unit:
            h = dt / (1 << level)
            ok, v1, v2 = _newton(ev, p1, p2, h, tol, max_newton)
            if not ok:
                if level == max_cuts:
                    status, tf, f1, f2 = 2, (k - 1 + pos / unit) * dt, q1, q2
                    break
                level += 1                     # retry as two half steps
                continue
            p1, p2 = ev[3] * v1 + ev[4] * v2, ev[4] * v1 + ev[5] * v2
            q1, q2 = q1 + h * v1, q2 + h * v2
            pos += 1 << (max_cuts - level)
            i, j, dx, dy = _locate(q1, q2, usable, x0, y0, hx, hy)
            if i < 0:
                status, tf, f1, f2 = 1, (k - 1 + pos / unit) * dt, q1, q2
                break
            ev = _eval(C, i, j, dx, dy)
            while level > 0 and pos % (1 << (max_cuts - level + 1)) == 0:
                level -= 1                     # both halves done: back to the parent's size
        if status != 0:
            k_fail = k
            if last != k - 1:
                T[n], Q[n, 0], Q[n, 1], P[n, 0], P[n, 1] = (k - 1) * dt, s1, s2, sp1, sp2
                E[n] = _energy(sev, sp1, sp2)
                n += 1
            break
        if k % save_every == 0 or k == n_steps:
            T[n], Q[n, 0], Q[n, 1], P[n, 0], P[n, 1] = k * dt, q1, q2, p1, p2
            E[n] = _energy(ev, p1, p2)
            n, last = n + 1, k
    return T[:n], Q[:n], P[:n], E[:n], status, k_fail, tf, f1, f2


def _where(q) -> str:
    return "[" + ", ".join(f"{x:.6g}" for x in q) + "]"


def integrate_table_2d(table: Table2D, q0, v0, dt: float, n_steps: int, save_every: int = 1,
                       tol: float = 1e-13, max_newton: int = 30, max_cuts: int = 4):
    """(times, Q (n_out, 2), P (n_out, 2), E (n_out,), steps done): the α = 0 integrator on
    the table from (q₀, q̇₀), saving every ``save_every`` steps and the last. InputError when
    q₀ or the trajectory is outside the usable cells (the slow manifold's sampled region) or
    Newton fails; its ``states`` attribute holds the (times, Q, P) reached."""
    q0 = np.asarray(q0, dtype=np.float64).reshape(-1)
    v0 = np.asarray(v0, dtype=np.float64).reshape(-1)
    if q0.shape != (2,) or v0.shape != (2,) or not dt > 0 or n_steps < 0 or save_every < 1 \
            or max_cuts < 0 or max_cuts > 30:
        raise InputError(f"integrate_table_2d needs q0 and v0 of 2 entries, dt > 0, n_steps ≥ "
                         f"0, save_every ≥ 1 and 0 ≤ max_cuts ≤ 30, got shapes {q0.shape}, "
                         f"{v0.shape}, dt = {dt}, n_steps = {n_steps}, save_every = "
                         f"{save_every}, max_cuts = {max_cuts}; fix the arguments.")
    region = (f"the slow manifold's sampled region (the usable cells of the table over "
              f"{_where(table.lo)}–{_where(table.hi)})")
    if not table.contains(q0):
        raise InputError(f"the start q0 = {_where(q0)} is outside {region}; start inside it, "
                         f"or sample a wider region.")
    p0 = table.terms(q0).mass @ v0
    T, Q, P, E, status, k, tf, f1, f2 = _run(
        q0[0], q0[1], p0[0], p0[1], float(dt), int(n_steps), int(save_every), *table.arrays(),
        float(tol), int(max_newton), int(max_cuts))
    if status == 1:
        err = InputError(f"the reduced trajectory left {region} at step {k} (t = {tf:.6g}, "
                         f"q = {_where((f1, f2))}); start inside it, lower the energy, or "
                         f"sample a wider region.")
    elif status == 2:
        err = InputError(f"Newton did not solve the reduced step {k} (t = {tf:.6g}, q = "
                         f"{_where((f1, f2))}) even with Δt/2^{max_cuts} = "
                         f"{dt / 2 ** max_cuts:.3g}; lower the time step.")
    else:
        return T, Q, P, E, int(n_steps)
    err.states = (T, Q, P)
    raise err
