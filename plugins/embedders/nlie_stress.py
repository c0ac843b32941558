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
    K = f'' u u^T + (f'/r)(I - u u^T);  H_ii += K, H_jj += K, H_ij = H_ji -= K.
The Hessian is assembled in block-sparse (BSR, d x d blocks) form; its pattern is fixed.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import numba
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


@njit(cache=True)
def _fill_hessian_blocks(Q, pi, pj, g, w, alpha, pos_ij, pos_ji, pos_diag, data):
    n, d = Q.shape
    data[:] = 0.0
    diff = np.empty(d)
    for p in range(pi.size):
        i = pi[p]
        j = pj[p]
        r2 = 0.0
        for k in range(d):
            diff[k] = Q[i, k] - Q[j, k]
            r2 += diff[k] * diff[k]
        r = np.sqrt(r2)
        gp = g[p]
        fp = alpha * (r / gp - 1.0) / gp
        fpp = alpha / (gp * gp)
        if alpha < 1.0:
            fp -= (1.0 - alpha) * (gp / r - 1.0) * gp / r2
            fpp += (1.0 - alpha) * (3.0 * gp * gp / (r2 * r2) - 2.0 * gp / (r2 * r))
        fp *= w[p]
        fpp *= w[p]
        a = fp / r
        b = (fpp - a) / r2
        for k in range(d):
            for m in range(d):
                K = b * diff[k] * diff[m]
                if k == m:
                    K += a
                data[pos_ij[p], k, m] -= K
                data[pos_ji[p], k, m] -= K
                data[pos_diag[i], k, m] += K
                data[pos_diag[j], k, m] += K


class StressHessian:
    """Fixed block-sparse pattern of the NLIE Hessian for given pairs; ``assemble(Q)`` -> BSR."""

    def __init__(self, n: int, d: int, pi: np.ndarray, pj: np.ndarray):
        P = pi.size
        rows = np.concatenate([pi, pj, np.arange(n)])
        cols = np.concatenate([pj, pi, np.arange(n)])
        ids = np.arange(1, 2 * P + n + 1, dtype=np.int64)
        A = sp.coo_matrix((ids, (rows, cols)), shape=(n, n)).tocsr()
        A.sort_indices()
        pos = np.empty(A.nnz, np.int64)
        pos[A.data - 1] = np.arange(A.nnz)
        self.pos_ij, self.pos_ji, self.pos_diag = pos[:P], pos[P:2 * P], pos[2 * P:]
        self.indptr, self.indices = A.indptr, A.indices
        self.n, self.d = n, d
        self.data = np.zeros((A.nnz, d, d))

    def assemble(self, Q, pi, pj, g, w, alpha) -> sp.bsr_matrix:
        _fill_hessian_blocks(Q, pi, pj, g, w, alpha, self.pos_ij, self.pos_ji, self.pos_diag,
                             self.data)
        nd = self.n * self.d
        return sp.bsr_matrix((self.data, self.indices, self.indptr), shape=(nd, nd))

    def diagonal_blocks(self) -> np.ndarray:
        return self.data[self.pos_diag]


def stress_hessian(Q, pi, pj, g, w, alpha) -> sp.csr_matrix:
    """Convenience: the (N d, N d) Hessian of E_S at Q as CSR (for tests and small problems)."""
    n, d = Q.shape
    return StressHessian(n, d, pi, pj).assemble(Q, pi, pj, g, w, alpha).tocsr()
