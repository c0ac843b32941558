"""Fused d = 2 kernels of the local max-ent (LME) basis functions: dual solve and derivatives.

The same mathematics as the general kernels of :mod:`.lme_kernels` (see its docstring for the
notation and formulas), specialised to d = 2, the hot case: every sum over the support nodes
that one step needs is accumulated in one pass (r and J: 5 sums; the derivative terms: 11),
2×2 systems are solved in closed form and the node data live in separate contiguous arrays
(y0_a, y1_a, b_a = -β_a|y_a|², β_a), so that every loop over the nodes vectorises. The general
kernels make ~12 passes per Newton step and ~25 for the derivatives.

Newton converges quadratically, so after the first one or two steps the exponents change by
little: a trial λ + Δ then gets its weights as p_a(λ) e^{Δ·y_a} with a Taylor polynomial
(:func:`_scaled`), not exponentials. Per point (γ = 0.8, ~65 support nodes) this makes
~2.4 passes of exponentials and ~2.8 of polynomials instead of ~4.1 of exponentials.
"""
from __future__ import annotations

import numba as nb
import numpy as np

from .small_math import FAST as _FAST
from .small_math import CONTRACT, exp_shifted

#: initial largest change of any exponent f_a in one Newton step (the cap then adapts)
MAX_EXPONENT_STEP = 20.0
#: largest |Δλ·y_a| for which the weights are updated by a Taylor polynomial, not exponentials
POLY_MAX = 0.35
#: status codes, as in lme_kernels
OK, NO_SUPPORT, NOT_CONVERGED, SINGULAR = 0, 1, 2, 3


@nb.njit(cache=True, inline="always", fastmath=_FAST)
def _moments(w, y0, y1, k):
    """Σ w_a, Σ w_a y_a (2) and Σ w_a y_a⊗y_a (3 entries), one pass."""
    z = s0 = s1 = s00 = s01 = s11 = 0.0
    for a in range(k):
        wa = w[a]
        u = wa * y0[a]
        v = wa * y1[a]
        z += wa
        s0 += u
        s1 += v
        s00 += u * y0[a]
        s01 += u * y1[a]
        s11 += v * y1[a]
    return z, s0, s1, s00, s01, s11


@nb.njit(cache=True, inline="always", fastmath=_FAST)
def _partition(y0, y1, b, k, l0, l1, p, ib):
    """Weights exp(f_a - max f) into p (f_a = b_a + λ·y_a); returns log Z and the moments."""
    fmax = -np.inf
    for a in range(k):
        f = b[a] + l0 * y0[a] + l1 * y1[a]
        p[a] = f
        fmax = max(fmax, f)
    if not np.isfinite(fmax):
        return np.inf, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0
    exp_shifted(p, k, fmax, ib)
    z, s0, s1, s00, s01, s11 = _moments(p, y0, y1, k)
    return fmax + np.log(z), z, s0, s1, s00, s01, s11


@nb.njit(cache=True, inline="always")
def _inverse(j00, j01, j11):
    """Inverse (i00, i01, i11) of the SPD 2×2 matrix J, ok=False where it is numerically
    singular (the Cholesky test of :func:`small_math.cholesky`: pivots > 1e-14 max J_ii)."""
    scale = max(abs(j00), abs(j11))
    if not j00 > 1e-14 * scale or scale == 0.0:
        return False, 0.0, 0.0, 0.0
    piv = j11 - j01 * j01 / j00
    if not piv > 1e-14 * scale:
        return False, 0.0, 0.0, 0.0
    det = j00 * piv
    return True, j11 / det, -j01 / det, j00 / det


@nb.njit(cache=True, fastmath=CONTRACT)
def _scaled(p, q, y0, y1, k, d0, d1, umax):
    """q_a = p_a e^{u_a}, u_a = Δ·y_a, for max |u_a| ≤ umax ≤ POLY_MAX, without exponentials.

    Taylor polynomial of e^u of a degree chosen from umax so that the truncation,
    |u|^(n+1)/(n+1)!, stays below 3e-17 relative (3, 6, 9 or 13 for umax ≤ 1e-4, 0.01, 0.1,
    0.35).
    """
    if umax <= 1e-4:
        for a in range(k):
            u = d0 * y0[a] + d1 * y1[a]
            q[a] = p[a] * (1.0 + u * (1.0 + u * (0.5 + u * (1.0 / 6.0))))
    elif umax <= 0.01:
        for a in range(k):
            u = d0 * y0[a] + d1 * y1[a]
            e = 1.0 / 720.0
            e = e * u + 1.0 / 120.0
            e = e * u + 1.0 / 24.0
            e = e * u + 1.0 / 6.0
            e = e * u + 0.5
            e = e * u + 1.0
            q[a] = p[a] * (e * u + 1.0)
    elif umax <= 0.1:
        for a in range(k):
            u = d0 * y0[a] + d1 * y1[a]
            e = 1.0 / 362880.0
            e = e * u + 1.0 / 40320.0
            e = e * u + 1.0 / 5040.0
            e = e * u + 1.0 / 720.0
            e = e * u + 1.0 / 120.0
            e = e * u + 1.0 / 24.0
            e = e * u + 1.0 / 6.0
            e = e * u + 0.5
            e = e * u + 1.0
            q[a] = p[a] * (e * u + 1.0)
    else:
        for a in range(k):
            u = d0 * y0[a] + d1 * y1[a]
            e = 1.0 / 6227020800.0
            e = e * u + 1.0 / 479001600.0
            e = e * u + 1.0 / 39916800.0
            e = e * u + 1.0 / 3628800.0
            e = e * u + 1.0 / 362880.0
            e = e * u + 1.0 / 40320.0
            e = e * u + 1.0 / 5040.0
            e = e * u + 1.0 / 720.0
            e = e * u + 1.0 / 120.0
            e = e * u + 1.0 / 24.0
            e = e * u + 1.0 / 6.0
            e = e * u + 0.5
            e = e * u + 1.0
            q[a] = p[a] * (e * u + 1.0)


@nb.njit(cache=True, fastmath=_FAST)
def solve_dual_2d(y0, y1, b, k, tol, max_iter, lam, p, q, ib):
    """Minimise log Z over λ (2,) for one point; fill p[:k] with p_a(λ*). Returns a status.

    Same algorithm as :func:`lme_kernels.solve_dual`: Newton steps -J⁻¹r, the exponent cap,
    Armijo backtracking on log Z, steepest descent where J is singular. A trial λ + Δ whose
    exponent changes u_a = Δ·y_a are all below POLY_MAX gets its weights as p_a e^{u_a} with a
    Taylor polynomial (:func:`_scaled`) instead of exponentials: all steps but the first one
    or two, as Newton converges quadratically. ``lam`` holds the starting multiplier on entry
    and λ* on exit; q (≥k) is scratch.
    """
    if k <= 2:
        return NO_SUPPORT
    ymax = 0.0
    for a in range(k):
        ymax = max(ymax, y0[a] * y0[a] + y1[a] * y1[a])
    ymax = np.sqrt(ymax)
    cap = MAX_EXPONENT_STEP
    l0, l1 = lam[0], lam[1]
    w, v = p, q  # current (unnormalised, sum z) and trial weights
    logz, z, s0, s1, s00, s01, s11 = _partition(y0, y1, b, k, l0, l1, w, ib)
    for _ in range(max_iter):
        iz = 1.0 / z
        r0 = s0 * iz
        r1 = s1 * iz
        if np.sqrt(r0 * r0 + r1 * r1) < tol:
            for a in range(k):
                p[a] = w[a] * iz
            lam[0], lam[1] = l0, l1
            return OK
        ok, i00, i01, i11 = _inverse(s00 * iz - r0 * r0, s01 * iz - r0 * r1,
                                     s11 * iz - r1 * r1)
        capped = False
        if ok:
            d0 = -(i00 * r0 + i01 * r1)
            d1 = -(i01 * r0 + i11 * r1)
        else:
            # J singular: (nearly) all weight on one node. Steepest descent -r, stretched to
            # the exponent cap, moves weight towards the other side of x.
            smax = 0.0
            for a in range(k):
                smax = max(smax, abs(r0 * y0[a] + r1 * y1[a]))
            if not smax > 0.0:
                return NOT_CONVERGED
            capped = True
            d0 = -r0 * (cap / smax)
            d1 = -r1 * (cap / smax)
        # cap the change of the exponents, max_a |Δ·y_a| ≤ cap (see lme_kernels.solve_dual)
        sn = np.sqrt(d0 * d0 + d1 * d1)
        if sn * ymax > cap:
            smax = 0.0
            for a in range(k):
                smax = max(smax, abs(d0 * y0[a] + d1 * y1[a]))
            if smax > cap:
                capped = True
                d0 *= cap / smax
                d1 *= cap / smax
                sn *= cap / smax
        slope = r0 * d0 + r1 * d1
        t = 1.0
        accepted = False
        for _ls in range(60):
            umax = t * sn * ymax
            if umax <= POLY_MAX:
                _scaled(w, v, y0, y1, k, t * d0, t * d1, umax)
                zt, t0, t1, t00, t01, t11 = _moments(v, y0, y1, k)
                logz_t = logz + np.log(zt * iz)
            else:
                logz_t, zt, t0, t1, t00, t01, t11 = _partition(y0, y1, b, k, l0 + t * d0,
                                                               l1 + t * d1, v, ib)
            if logz_t <= logz + 1e-4 * t * slope + 1e-13 * (1.0 + abs(logz)):
                accepted = True
                break
            t *= 0.5
        if not accepted or not np.isfinite(logz_t):
            return NOT_CONVERGED
        l0 += t * d0
        l1 += t * d1
        logz = logz_t
        z, s0, s1, s00, s01, s11 = zt, t0, t1, t00, t01, t11
        w, v = v, w
        # trust-region-like cap: grow it after a full capped step, shrink after backtracking
        if capped and t == 1.0:
            cap = min(2.0 * cap, 1e6)
        elif t < 1.0:
            cap = max(0.5 * cap, MAX_EXPONENT_STEP)
    return NOT_CONVERGED


@nb.njit(cache=True, fastmath=_FAST)
def derivatives_2d(y0, y1, beta, p, k, order, lo, grads, hess, g0, g1, h):
    """∇p_a into grads[2(lo + a) : 2(lo + a) + 2] (order ≥ 1) and H p_a, row-major, into
    hess[4(lo + a) : 4(lo + a) + 4] (order 2), d = 2; grads and hess are flat views of the
    (nnz, 2) and (nnz, 2, 2) outputs.

    Formulas of :mod:`.lme_kernels` (module docstring): g_a = r_β - 2β_a y_a + K y_a with
    K = (J_β - I) J⁻¹, ∇p_a = p_a g_a, and H p_a = p_a [g_a⊗g_a - G + 2(β̄ - β_a) I -
    Σ_k (J⁻¹y_a)_k S_k]. Scratch g0, g1 (≥k), h (3, ≥k): the terms are computed in
    contiguous arrays (vectorised loops) and then interleaved into grads and hess.
    Returns False if J(λ*) is numerically singular.
    """
    r0 = r1 = m00 = m01 = m11 = 0.0
    bbar = rb0 = rb1 = b00 = b01 = b11 = 0.0
    for a in range(k):
        pa = p[a]
        u = pa * y0[a]
        v = pa * y1[a]
        r0 += u
        r1 += v
        m00 += u * y0[a]
        m01 += u * y1[a]
        m11 += v * y1[a]
        ba = beta[a]
        bbar += ba * pa
        rb0 += ba * u
        rb1 += ba * v
        b00 += ba * u * y0[a]
        b01 += ba * u * y1[a]
        b11 += ba * v * y1[a]
    ok, i00, i01, i11 = _inverse(m00 - r0 * r0, m01 - r0 * r1, m11 - r1 * r1)
    if not ok:
        return False
    rb0 *= 2.0
    rb1 *= 2.0
    jb00 = 2.0 * b00 - 1.0
    jb01 = 2.0 * b01
    jb11 = 2.0 * b11 - 1.0
    # K = (J_β - I) J⁻¹
    k00 = jb00 * i00 + jb01 * i01
    k01 = jb00 * i01 + jb01 * i11
    k10 = jb01 * i00 + jb11 * i01
    k11 = jb01 * i01 + jb11 * i11
    for a in range(k):
        g0[a] = rb0 + (k00 - 2.0 * beta[a]) * y0[a] + k01 * y1[a]
    for a in range(k):
        g1[a] = rb1 + k10 * y0[a] + (k11 - 2.0 * beta[a]) * y1[a]
    for a in range(k):  # grads, hess: flat (nnz·2,), (nnz·4,) views, interleaved stores
        grads[2 * (lo + a)] = p[a] * g0[a]
        grads[2 * (lo + a) + 1] = p[a] * g1[a]
    if order < 2:
        return True
    G00 = G01 = G11 = 0.0
    S000 = S001 = S011 = S100 = S101 = S111 = 0.0  # S[m, i, j]
    for a in range(k):
        pa = p[a]
        a00 = pa * g0[a] * g0[a]
        a01 = pa * g0[a] * g1[a]
        a11 = pa * g1[a] * g1[a]
        tb = 2.0 * pa * beta[a]
        G00 += a00
        G01 += a01
        G11 += a11
        S000 += y0[a] * (a00 - tb)
        S001 += y0[a] * a01
        S011 += y0[a] * (a11 - tb)
        S100 += y1[a] * (a00 - tb)
        S101 += y1[a] * a01
        S111 += y1[a] * (a11 - tb)
    h00, h01, h11 = h[0], h[1], h[2]
    # one output array per loop: few runtime alias checks, so that each loop vectorises
    for a in range(k):
        j0 = i00 * y0[a] + i01 * y1[a]
        j1 = i01 * y0[a] + i11 * y1[a]
        h00[a] = p[a] * (g0[a] * g0[a] - G00 + 2.0 * (bbar - beta[a]) - j0 * S000 - j1 * S100)
    for a in range(k):
        j0 = i00 * y0[a] + i01 * y1[a]
        j1 = i01 * y0[a] + i11 * y1[a]
        h01[a] = p[a] * (g0[a] * g1[a] - G01 - j0 * S001 - j1 * S101)
    for a in range(k):
        j0 = i00 * y0[a] + i01 * y1[a]
        j1 = i01 * y0[a] + i11 * y1[a]
        h11[a] = p[a] * (g1[a] * g1[a] - G11 + 2.0 * (bbar - beta[a]) - j0 * S011 - j1 * S111)
    for a in range(k):
        hess[4 * (lo + a)] = h00[a]
        hess[4 * (lo + a) + 1] = h01[a]
        hess[4 * (lo + a) + 2] = h01[a]
        hess[4 * (lo + a) + 3] = h11[a]
    return True


@nb.njit(parallel=True, cache=True)
def lme_kernel_2d(points, visit, cell, starts, entries, entry_x, entry_r2, entry_beta, indptr,
                  tol, max_iter, order, indices, values, grads, hess, status):
    """d = 2 version of :func:`lme_kernels.lme_kernel` (same arguments and outputs)."""
    m = points.shape[0]
    grads_flat = grads.reshape(grads.size)
    hess_flat = hess.reshape(hess.size)
    chunk = 64
    n_chunks = (m + chunk - 1) // chunk
    for c in nb.prange(n_chunks):
        i0 = c * chunk
        i1 = min(m, i0 + chunk)
        cmax = 0
        for ii in range(i0, i1):
            ci = cell[visit[ii]]
            if ci >= 0:
                cmax = max(cmax, starts[ci + 1] - starts[ci])
        y0 = np.empty(cmax)
        y1 = np.empty(cmax)
        b = np.empty(cmax)
        bl = np.empty(cmax)
        ent = np.empty(cmax, dtype=np.int64)
        inside = np.empty(cmax, dtype=np.int64)
        p = np.empty(cmax)
        pq = np.empty(cmax)
        ib = np.empty(cmax, dtype=np.int64)
        lam = np.empty(2)
        g0 = np.empty(cmax)
        g1 = np.empty(cmax)
        h = np.empty((3, cmax))
        for ii in range(i0, i1):
            i = visit[ii]
            lo = indptr[i]
            k = indptr[i + 1] - lo
            ci = cell[i]
            x0 = points[i, 0]
            x1 = points[i, 1]
            if ci >= 0:
                # support nodes of the cell's candidates: a vectorised test, the compaction of
                # their entry numbers, then a gather (same order as support.scan)
                e0 = starts[ci]
                nc = starts[ci + 1] - e0
                for j in range(nc):
                    t0 = x0 - entry_x[0, e0 + j]
                    t1 = x1 - entry_x[1, e0 + j]
                    inside[j] = np.int64(t0 * t0 + t1 * t1 < entry_r2[e0 + j])
                q = 0
                for j in range(nc):
                    ent[q] = e0 + j
                    q += inside[j]
                for a in range(k):
                    e = ent[a]
                    t0 = x0 - entry_x[0, e]
                    t1 = x1 - entry_x[1, e]
                    be = entry_beta[e]
                    y0[a] = t0
                    y1[a] = t1
                    b[a] = -be * (t0 * t0 + t1 * t1)
                    bl[a] = be
            for q in range(k):
                indices[lo + q] = entries[ent[q]]
            lam[0] = 0.0
            lam[1] = 0.0
            st = solve_dual_2d(y0, y1, b, k, tol, max_iter, lam, p, pq, ib)
            status[i] = st
            for q in range(k):
                values[lo + q] = p[q]
            if st != OK or order == 0:
                continue
            if not derivatives_2d(y0, y1, bl, p, k, order, lo, grads_flat, hess_flat, g0, g1,
                                  h):
                status[i] = SINGULAR
