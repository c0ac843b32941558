"""Numba kernels of the local max-ent (LME) basis functions: dual Newton solve and derivatives.

Notation (thesis Box 2; Paper 1 eqs. (7), (A1)-(A4)), for one evaluation point x and its
support nodes a with y_a = x - x_a (stored transposed, yT[i, a], so that the loops over nodes
are innermost and vectorise):

    f_a = -β_a |y_a|² + λ·y_a,   p_a = exp(f_a) / Z,   Z = Σ_b exp(f_b),
    r = Σ_a p_a y_a = ∂ log Z/∂λ,   J = Σ_a p_a y_a⊗y_a - r⊗r = ∂r/∂λ,

and λ* = argmin_λ log Z (Newton with backtracking on log Z; converged when |r| < tol).

Derivatives with *nodal* β_a (derived from r(x, λ*(x)) ≡ 0; they reduce to
∇p_a = -p_a J⁻¹y_a for constant β). With β̄ = Σ β_c p_c, r_β = 2 Σ β_c p_c y_c and
J_β = 2 Σ β_c p_c y_c⊗y_c:

    Dλ* = J⁻¹ (J_β - I)
    ∇p_a = p_a g_a,   g_a = r_β - 2 β_a y_a + (J_β - I) J⁻¹ y_a
    H p_a = p_a [ g_a⊗g_a - G + 2(β̄ - β_a) I - Σ_k (J⁻¹y_a)_k S_k ]

with G = Σ_c p_c g_c⊗g_c and S_k = Σ_c p_c (y_c)_k (g_c⊗g_c - 2 β_c I), the term in S coming
from D²λ* = -J⁻¹ S (second derivative of r* ≡ 0). This is Paper 1 (A5)-(A7) generalised.
"""
from __future__ import annotations

import numba as nb
import numpy as np

from .small_math import FAST as _FAST
from .small_math import cholesky, cholesky_solve, exp_nonpositive
from .lme_last_step import SMALL_EXPONENT_STEP, small_step_converges

#: initial largest change of any exponent f_a in one Newton step (the cap then adapts)
MAX_EXPONENT_STEP = 20.0

#: status codes returned per point
OK, NO_SUPPORT, NOT_CONVERGED, SINGULAR = 0, 1, 2, 3


@nb.njit(cache=True, inline="always", fastmath=_FAST)
def _partition(yT, beta, d2, k, lam, p, r, J, ib):
    """At multiplier λ: unnormalised weights exp(f_a - max f) into p, r and J; returns log Z."""
    d = yT.shape[0]
    for a in range(k):
        p[a] = -beta[a] * d2[a]
    for j in range(d):
        lj = lam[j]
        yj = yT[j]
        for a in range(k):
            p[a] += lj * yj[a]
    fmax = -np.inf
    for a in range(k):
        fmax = max(fmax, p[a])
    if not np.isfinite(fmax):
        return np.inf
    for a in range(k):
        p[a] -= fmax
    exp_nonpositive(p, k, ib)
    z = 0.0
    for a in range(k):
        z += p[a]
    inv = 1.0 / z
    for i in range(d):
        yi = yT[i]
        s = 0.0
        for a in range(k):
            s += p[a] * yi[a]
        r[i] = s * inv
    for i in range(d):
        yi = yT[i]
        for j in range(i + 1):
            yj = yT[j]
            s = 0.0
            for a in range(k):
                s += p[a] * yi[a] * yj[a]
            J[i, j] = s * inv - r[i] * r[j]
            J[j, i] = J[i, j]
    return fmax + np.log(z)


@nb.njit(cache=True, fastmath=_FAST)
def solve_dual(yT, beta, d2, k, tol, max_iter, lam, p, mats, vecs, ib):
    """Minimise log Z over λ for one point; fill p[:k] with p_a(λ*). Returns a status code.

    ``lam`` (d,) holds the starting multiplier on entry and λ* on exit.

    yT (d, ≥k): yT[:, a] = x - x_a; beta β_a; d2 |y_a|²; scratch mats (≥2, d, d), vecs
    (≥4, d), ib (≥k,) int64. Newton steps -J⁻¹r (capped: no exponent f_a changes by more than
    a cap that starts at MAX_EXPONENT_STEP and doubles after full capped steps), halved until
    log Z decreases (Armijo, with round-off slack); each trial costs one pass of exponentials,
    reused by the next iteration when accepted. Where J is singular the step is steepest
    descent, -r. The last, tiny step updates the weights without exponentials
    (:mod:`.lme_last_step`). No convergence within ``max_iter`` or a non-finite log Z means the
    point is outside the convex hull of its support nodes (the dual has no minimiser).
    """
    d = yT.shape[0]
    if k <= d:
        return NO_SUPPORT
    J = mats[0]
    L = mats[1]
    trial = vecs[1]
    step = vecs[2]
    r = vecs[3]
    ymax = 0.0
    for a in range(k):
        ymax = max(ymax, d2[a])
    ymax = np.sqrt(ymax)
    cap = MAX_EXPONENT_STEP
    logz = _partition(yT, beta, d2, k, lam, p, r, J, ib)
    for _ in range(max_iter):
        rn = 0.0
        for i in range(d):
            rn += r[i] * r[i]
        if np.sqrt(rn) < tol:
            s = 0.0
            for a in range(k):
                s += p[a]
            inv = 1.0 / s
            for a in range(k):
                p[a] *= inv
            return OK
        capped = False
        if cholesky(J, L):
            cholesky_solve(L, r, step)
        else:
            # J singular: (nearly) all weight on one node. Steepest descent -r, stretched to
            # the exponent cap below, moves weight towards the other side of x.
            smax = 0.0
            for a in range(k):
                t = 0.0
                for i in range(d):
                    t += r[i] * yT[i, a]
                smax = max(smax, abs(t))
            if not smax > 0.0:
                return NOT_CONVERGED
            capped = True
            for i in range(d):
                step[i] = r[i] * (cap / smax)
        # Cap the change of the exponents, max_a |Δλ·y_a| ≤ MAX_EXPONENT_STEP: a nearly
        # singular J (weights concentrated on one node, e.g. in a gap between clusters of
        # nodes) would otherwise give a step no line search can recover from.
        sn = 0.0
        for i in range(d):
            step[i] = -step[i]
            sn += step[i] * step[i]
        if np.sqrt(sn) * ymax > cap:
            smax = 0.0
            for a in range(k):
                t = 0.0
                for i in range(d):
                    t += step[i] * yT[i, a]
                smax = max(smax, abs(t))
            if smax > cap:
                capped = True
                for i in range(d):
                    step[i] *= cap / smax
        if not capped and np.sqrt(sn) * ymax < SMALL_EXPONENT_STEP:
            if small_step_converges(yT, k, step, p, tol):  # the last step: no exponentials
                for i in range(d):
                    lam[i] += step[i]
                return OK
        slope = 0.0
        for i in range(d):
            slope += r[i] * step[i]
        t = 1.0
        accepted = False
        new_logz = logz
        for _ls in range(60):
            for i in range(d):
                trial[i] = lam[i] + t * step[i]
            new_logz = _partition(yT, beta, d2, k, trial, p, r, J, ib)
            if new_logz <= logz + 1e-4 * t * slope + 1e-13 * (1.0 + abs(logz)):
                accepted = True
                break
            t *= 0.5
        if not accepted or not np.isfinite(new_logz):
            return NOT_CONVERGED
        for i in range(d):
            lam[i] = trial[i]
        logz = new_logz
        # trust-region-like cap: grow it after a full capped step, shrink after backtracking
        if capped and t == 1.0:
            cap = min(2.0 * cap, 1e6)
        elif t < 1.0:
            cap = max(0.5 * cap, MAX_EXPONENT_STEP)
    return NOT_CONVERGED


@nb.njit(cache=True, fastmath=_FAST)
def derivatives(yT, beta, p, k, order, lo, grads, hess, gT, jT, hT, mats, vecs, S):
    """∇p_a into grads[lo + a] and, if order ≥ 2, H p_a into hess[lo + a] (module docstring).

    Leaves K = (J_β - I) J⁻¹ = (Dλ*)ᵀ in mats[4] (with order 0 it only computes K).
    Returns False if J(λ*) is numerically singular (weights concentrated on one node).

    Scratch: gT, jT (d, ≥k), hT (d, d, ≥k), mats (≥5, d, d), vecs (≥3, d), S (d, d, d).
    """
    d = yT.shape[0]
    J, Jb, L, Jinv, K = mats[0], mats[1], mats[2], mats[3], mats[4]
    r, rb, col = vecs[0], vecs[1], vecs[2]
    bbar = 0.0
    for a in range(k):
        bbar += beta[a] * p[a]
    for i in range(d):
        yi = yT[i]
        s = 0.0
        sb = 0.0
        for a in range(k):
            s += p[a] * yi[a]
            sb += beta[a] * p[a] * yi[a]
        r[i] = s
        rb[i] = 2.0 * sb
    for i in range(d):
        yi = yT[i]
        for j in range(i + 1):
            yj = yT[j]
            s = 0.0
            sb = 0.0
            for a in range(k):
                pyy = p[a] * yi[a] * yj[a]
                s += pyy
                sb += beta[a] * pyy
            J[i, j] = s - r[i] * r[j]
            J[j, i] = J[i, j]
            Jb[i, j] = 2.0 * sb
            Jb[j, i] = Jb[i, j]
    if not cholesky(J, L):
        return False
    for j in range(d):
        r[:] = 0.0
        r[j] = 1.0
        cholesky_solve(L, r, col)
        for i in range(d):
            Jinv[i, j] = col[i]
    for i in range(d):  # K = (J_β - I) J⁻¹
        for j in range(d):
            s = -Jinv[i, j]
            for m in range(d):
                s += Jb[i, m] * Jinv[m, j]
            K[i, j] = s
    if order == 0:
        return True
    for i in range(d):  # g_a = r_β - 2 β_a y_a + K y_a
        gi = gT[i]
        yi = yT[i]
        rbi = rb[i]
        for a in range(k):
            gi[a] = rbi - 2.0 * beta[a] * yi[a]
        for m in range(d):
            kim = K[i, m]
            ym = yT[m]
            for a in range(k):
                gi[a] += kim * ym[a]
        for a in range(k):
            grads[lo + a, i] = p[a] * gi[a]
    if order < 2:
        return True
    G = mats[1]  # J_β no longer needed (row views below keep the inner loops vectorisable)
    for i in range(d):
        gi = gT[i]
        for j in range(i + 1):
            gj = gT[j]
            s = 0.0
            for a in range(k):
                s += p[a] * gi[a] * gj[a]
            G[i, j] = s
            for m in range(d):
                ym = yT[m]
                s = 0.0
                if i == j:
                    for a in range(k):
                        s += p[a] * ym[a] * (gi[a] * gi[a] - 2.0 * beta[a])
                else:
                    for a in range(k):
                        s += p[a] * ym[a] * gi[a] * gj[a]
                S[m, i, j] = s
    for i in range(d):  # j_a = J⁻¹ y_a
        ji = jT[i]
        for a in range(k):
            ji[a] = 0.0
        for m in range(d):
            jim = Jinv[i, m]
            ym = yT[m]
            for a in range(k):
                ji[a] += jim * ym[a]
    for i in range(d):  # H p_a, component (i, j), for all a at once
        gi = gT[i]
        for j in range(i + 1):
            gj = gT[j]
            gij = G[i, j]
            hij = hT[i, j]
            for a in range(k):
                hij[a] = gi[a] * gj[a] - gij
            if i == j:
                for a in range(k):
                    hij[a] += 2.0 * (bbar - beta[a])
            for m in range(d):
                smij = S[m, i, j]
                jm = jT[m]
                for a in range(k):
                    hij[a] -= jm[a] * smij
            for a in range(k):
                hij[a] *= p[a]
    for a in range(k):
        for i in range(d):
            for j in range(i + 1):
                hess[lo + a, i, j] = hT[i, j, a]
                hess[lo + a, j, i] = hT[i, j, a]
    return True


@nb.njit(parallel=True, cache=True)
def lme_kernel(points, visit, cell, starts, entries, entry_x, entry_r2, entry_beta, indptr,
               tol, max_iter, order, indices, values, grads, hess, status):
    """LME values (and derivatives up to ``order``) at all points, in CSR layout, in parallel.

    The first seven arguments are :meth:`support.Cells.args`, ``entry_beta`` is β of each
    entry (``beta[entries]``, contiguous like ``entry_r2``); ``indptr`` comes from
    :meth:`support.Cells.count`; the kernel fills ``indices`` (support nodes), ``values``,
    ``grads`` ((nnz, d), if order ≥ 1) and ``hess`` ((nnz, d, d), if order 2).
    ``status[i]`` receives OK, NO_SUPPORT or NOT_CONVERGED. (d = 2 has its own, faster kernel:
    :func:`.lme_kernel_2d.lme_kernel_2d`.) Points are processed in the order
    ``visit`` (nearby points together), in chunks that share scratch memory.
    """
    m, d = points.shape
    chunk = 64
    n_chunks = (m + chunk - 1) // chunk
    for c in nb.prange(n_chunks):
        i0 = c * chunk
        i1 = min(m, i0 + chunk)
        kmax = 0
        cmax = 0  # most candidates in a cell: the scan writes every candidate, then keeps k
        for ii in range(i0, i1):
            kmax = max(kmax, indptr[visit[ii] + 1] - indptr[visit[ii]])
            ci = cell[visit[ii]]
            if ci >= 0:
                cmax = max(cmax, starts[ci + 1] - starts[ci])
        yT = np.empty((d, cmax))
        ent = np.empty(cmax, dtype=np.int64)
        gT = np.empty((d, kmax))
        jT = np.empty((d, kmax))
        hT = np.empty((d, d, kmax) if order >= 2 else (d, d, 0))
        bl = np.empty(cmax)
        d2 = np.empty(cmax)
        mats = np.empty((5, d, d))
        vecs = np.empty((4, d))
        S = np.empty((d, d, d))
        lam = np.empty(d)
        ib = np.empty(kmax, dtype=np.int64)
        p = np.empty(kmax)  # contiguous scratch: the kernels vectorise over it
        for ii in range(i0, i1):
            i = visit[ii]
            lo = indptr[i]
            k = indptr[i + 1] - lo
            ci = cell[i]
            if ci >= 0:
                # branch-free scan of the cell: store every candidate at slot q, advance q
                # only for support nodes (|x - x_a|² < r_a²); same order as support.scan
                q = 0
                for e in range(starts[ci], starts[ci + 1]):
                    s = 0.0
                    for j in range(d):
                        t = points[i, j] - entry_x[j, e]
                        yT[j, q] = t
                        s += t * t
                    d2[q] = s
                    bl[q] = entry_beta[e]
                    ent[q] = e
                    q += 1 if s < entry_r2[e] else 0
            for q in range(k):
                indices[lo + q] = entries[ent[q]]
            lam[:] = 0.0
            st = solve_dual(yT, bl, d2, k, tol, max_iter, lam, p, mats, vecs, ib)
            status[i] = st
            for q in range(k):
                values[lo + q] = p[q]
            if st != OK or order == 0:
                continue
            if not derivatives(yT, bl, p, k, order, lo, grads, hess, gT, jT, hT, mats, vecs,
                               S):
                status[i] = SINGULAR
