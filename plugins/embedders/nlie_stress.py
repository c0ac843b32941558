"""Sparse NLIE stress energy, gradient and Hessian (thesis Appendix C, L3127-3160).

    E_S(Q) = alpha E1 + (1 - alpha) E2,
    E1 = 1/2 sum_i sum_{j in N(i)} (|q_ij| / |x_ij| - 1)^2,
    E2 = 1/2 sum_i sum_{j in N(i)} (|x_ij| / |q_ij| - 1)^2,

q_ij = q_i - q_j (embedding, (N, d)), |x_ij| the geodesic distance, N(i) the k_G geodesically
nearest points of x_i. The double sum is evaluated over unique pairs (i < j) with weight w = 2
when j in N(i) and i in N(j), else 1 (``geodesics.pairs_from_neighbors``); this is the thesis'
sum over N(i) and the dual list N~(i).

Per pair, with r = |q_ij|, g = |x_ij|, u = q_ij / r and f(r) the pair energy:
    f'(r)  = w [alpha (r/g - 1)/g - (1 - alpha)(g/r - 1) g / r^2]
    f''(r) = w [alpha / g^2 + (1 - alpha)(3 g^2 / r^4 - 2 g / r^3)]
    dE/dq_i = f' u = -dE/dq_j,
    K = f'' u u^T + (f'/r)(I - u u^T) = a I + b q_ij q_ij^T,  a = f'/r,  b = (f'' - a) / r^2;
    H_ii += K, H_jj += K, H_ij = H_ji -= K.
The Hessian is never assembled: it is kept as the two numbers (a, b) per pair (``pair_curvatures``)
and applied pair by pair (``hessian_matvec``), O(P) memory and time for P pairs. Its "convex
part" replaces a and f'' by their positive parts (K clipped to positive semidefinite), a
Gauss-Newton-like matrix used where the true Hessian is indefinite. ``NearPairPreconditioner``
factorises the convex Hessian of the few nearest pairs of every point (sparse LU).
"""
from __future__ import annotations

import numba
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit, prange


@njit(cache=True)
def _energy_grad_range(Q, pi, pj, g, w, alpha, start, stop, grad):
    d = Q.shape[1]
    E = 0.0
    diff = np.empty(d)
    for p in range(start, stop):
        i = pi[p]
        j = pj[p]
        r2 = 0.0
        for k in range(d):
            diff[k] = Q[i, k] - Q[j, k]
            r2 += diff[k] * diff[k]
        r = np.sqrt(r2)
        gp = g[p]
        e1 = r / gp - 1.0
        fp = alpha * e1 / gp
        E += w[p] * 0.5 * alpha * e1 * e1
        if alpha < 1.0:
            e2 = gp / r - 1.0
            E += w[p] * 0.5 * (1.0 - alpha) * e2 * e2
            fp -= (1.0 - alpha) * e2 * gp / r2
        c = w[p] * fp / r
        for k in range(d):
            v = c * diff[k]
            grad[i, k] += v
            grad[j, k] -= v
    return E


def stress_energy_grad(Q, pi, pj, g, w, alpha):
    """Return (E_S, dE_S/dQ (N, d)); pairs split in chunks with private gradients (threads)."""
    n_chunks = max(1, min(numba.get_num_threads(), pi.size // 10000))
    return _stress_energy_grad_chunks(Q, pi, pj, g, w, alpha, n_chunks)


@njit(cache=True, parallel=True)
def _stress_energy_grad_chunks(Q, pi, pj, g, w, alpha, n_chunks):
    n, d = Q.shape
    grads = np.zeros((n_chunks, n, d))
    energies = np.zeros(n_chunks)
    step = (pi.size + n_chunks - 1) // n_chunks
    for c in prange(n_chunks):
        energies[c] = _energy_grad_range(Q, pi, pj, g, w, alpha, c * step,
                                         min(pi.size, (c + 1) * step), grads[c])
    grad = grads[0]
    for c in range(1, n_chunks):
        grad += grads[c]
    return energies.sum(), grad


@njit(cache=True)
def stress_energy(Q, pi, pj, g, w, alpha):
    n, d = Q.shape
    E = 0.0
    for p in range(pi.size):
        i = pi[p]
        j = pj[p]
        r2 = 0.0
        for k in range(d):
            t = Q[i, k] - Q[j, k]
            r2 += t * t
        r = np.sqrt(r2)
        e1 = r / g[p] - 1.0
        E += w[p] * 0.5 * alpha * e1 * e1
        if alpha < 1.0:
            e2 = g[p] / r - 1.0
            E += w[p] * 0.5 * (1.0 - alpha) * e2 * e2
    return E


@njit(cache=True, parallel=True)
def _pair_curvatures(Q, pi, pj, g, w, alpha, convex, a_out, b_out):
    d = Q.shape[1]
    for p in prange(pi.size):
        i = pi[p]
        j = pj[p]
        r2 = 0.0
        for k in range(d):
            t = Q[i, k] - Q[j, k]
            r2 += t * t
        r = np.sqrt(r2)
        gp = g[p]
        fp = alpha * (r / gp - 1.0) / gp
        fpp = alpha / (gp * gp)
        if alpha < 1.0:
            fp -= (1.0 - alpha) * (gp / r - 1.0) * gp / r2
            fpp += (1.0 - alpha) * (3.0 * gp * gp / (r2 * r2) - 2.0 * gp / (r2 * r))
        a = w[p] * fp / r
        fpp *= w[p]
        if convex:
            a = max(a, 0.0)
            fpp = max(fpp, 0.0)
        a_out[p] = a
        b_out[p] = (fpp - a) / r2


def pair_curvatures(Q, pi, pj, g, w, alpha, *, convex: bool = False, out=None):
    """Per-pair Hessian blocks K_p = a_p I + b_p q_ij q_ij^T of E_S at Q; returns (a, b).

    ``convex``: clip the two eigenvalues of K_p (f'' along q_ij, f'/r across) at zero, giving a
    positive semidefinite Hessian. ``out``: optional (a, b) arrays of length P to fill.
    """
    a, b = out if out is not None else (np.empty(pi.size), np.empty(pi.size))
    _pair_curvatures(Q, pi, pj, g, w, alpha, bool(convex), a, b)
    return a, b


@njit(cache=True, parallel=True)
def _hessian_matvec_chunks(Q, pi, pj, a, b, V, n_chunks):
    n, d = Q.shape
    outs = np.zeros((n_chunks, n, d))
    step = (pi.size + n_chunks - 1) // n_chunks
    for c in prange(n_chunks):
        out = outs[c]
        dq = np.empty(d)
        dv = np.empty(d)
        for p in range(c * step, min(pi.size, (c + 1) * step)):
            i = pi[p]
            j = pj[p]
            s = 0.0
            for k in range(d):
                dq[k] = Q[i, k] - Q[j, k]
                dv[k] = V[i, k] - V[j, k]
                s += dq[k] * dv[k]
            s *= b[p]
            for k in range(d):
                t = a[p] * dv[k] + s * dq[k]
                out[i, k] += t
                out[j, k] -= t
    res = outs[0]
    for c in range(1, n_chunks):
        res += outs[c]
    return res


def hessian_matvec(Q, pi, pj, a, b, V) -> np.ndarray:
    """H V for the Hessian given by pair curvatures (a, b) at Q; V and result (N, d)."""
    n_chunks = max(1, min(numba.get_num_threads(), pi.size // 10000))
    return _hessian_matvec_chunks(Q, pi, pj, a, b, V, n_chunks)


@njit(cache=True)
def hessian_diagonal_blocks(Q, pi, pj, a, b):
    """The (N, d, d) diagonal blocks H_ii = sum of K_p over the pairs p holding i."""
    n, d = Q.shape
    D = np.zeros((n, d, d))
    dq = np.empty(d)
    for p in range(pi.size):
        i = pi[p]
        j = pj[p]
        for k in range(d):
            dq[k] = Q[i, k] - Q[j, k]
        for k in range(d):
            for m in range(d):
                K = b[p] * dq[k] * dq[m]
                if k == m:
                    K += a[p]
                D[i, k, m] += K
                D[j, k, m] += K
    return D


@njit(cache=True)
def _pair_blocks_coo(Q, pi, pj, a, b):
    n, d = Q.shape
    m = 4 * pi.size * d * d
    rows = np.empty(m, np.int64)
    cols = np.empty(m, np.int64)
    vals = np.empty(m)
    e = 0
    dq = np.empty(d)
    for p in range(pi.size):
        i = pi[p]
        j = pj[p]
        for k in range(d):
            dq[k] = Q[i, k] - Q[j, k]
        for k in range(d):
            for l in range(d):
                K = b[p] * dq[k] * dq[l]
                if k == l:
                    K += a[p]
                for (r, c, s) in ((i, i, 1.0), (j, j, 1.0), (i, j, -1.0), (j, i, -1.0)):
                    rows[e] = r * d + k
                    cols[e] = c * d + l
                    vals[e] = s * K
                    e += 1
    return rows, cols, vals


def pair_hessian_matrix(Q, pi, pj, a, b) -> sp.csc_matrix:
    """The (N d, N d) sparse matrix sum_p K_p (e_i - e_j)(e_i - e_j)^T for pair curvatures."""
    n, d = Q.shape
    rows, cols, vals = _pair_blocks_coo(Q, pi, pj, a, b)
    return sp.csc_matrix((vals, (rows, cols)), shape=(n * d, n * d))


def stress_hessian(Q, pi, pj, g, w, alpha) -> sp.csr_matrix:
    """Convenience: the (N d, N d) Hessian of E_S at Q as CSR (for tests and small problems)."""
    a, b = pair_curvatures(Q, pi, pj, g, w, alpha)
    return pair_hessian_matrix(Q, pi, pj, a, b).tocsr()


@njit(cache=True)
def near_pairs(pi, pj, g, n, k):
    """Mask of the pairs (i, j) with j among the k nearest partners of i, or i among those of j.

    "Nearest" in the given distances g; the k smallest incident g per point are kept in a small
    insertion-sorted list, O(P k).
    """
    best = np.full((n, k), np.inf)
    for p in range(pi.size):
        for i in (pi[p], pj[p]):
            v = g[p]
            if v < best[i, k - 1]:
                m = k - 1
                while m > 0 and best[i, m - 1] > v:
                    best[i, m] = best[i, m - 1]
                    m -= 1
                best[i, m] = v
    mask = np.empty(pi.size, np.bool_)
    for p in range(pi.size):
        mask[p] = g[p] <= max(best[pi[p], k - 1], best[pj[p], k - 1])
    return mask


class NearPairPreconditioner:
    """M^-1 for the NLIE Hessian: sparse LU of s H_near + shift I.

    H_near is the convex Hessian restricted to the ``near`` pairs (a few nearest per point), so M
    captures both the stiff short pairs (1/g^2 weights) and the smooth, long-wavelength modes of
    the embedding that point-wise (block-Jacobi) preconditioning leaves to CG; the scalar s
    matches the traces of M and of the full convex Hessian (whose diagonal is ``diag_trace``).
    Factor memory grows like that of a 2-D finite-element mesh with N nodes (near-linear).
    """

    def __init__(self, Q, pi, pj, a, b, near, diag_trace: float, shift_rel: float = 1e-8):
        H = pair_hessian_matrix(Q, pi[near], pj[near], a[near], b[near])
        s = diag_trace / max(H.diagonal().sum(), 1e-300)
        H = H * s
        self.scale = diag_trace / H.shape[0]
        H = H + sp.identity(H.shape[0], format="csc") * (shift_rel * self.scale)
        # symmetric positive definite: minimum-degree ordering of A + A^T, no pivoting
        self.lu = spla.splu(H.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                            options={"SymmetricMode": True})

    def __call__(self, r: np.ndarray) -> np.ndarray:
        return self.lu.solve(r)
