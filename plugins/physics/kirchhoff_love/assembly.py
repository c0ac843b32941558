"""Numba assembly of shell forces and stiffness matrices into scipy sparse (thesis Eq. 14–15).

DOF numbering 3a + i (node a, Cartesian component i). Stiffness: for each point block of the
AssemblyPlan (assembly_plan.py) the 3×3 node blocks K_ab of its points (pairs a ≤ b only; K is
symmetric, so K_ba = K_abᵀ is added at flush time) are accumulated in a dense local array over
the block's node set, which is then flushed into the precomputed block-CSR (scipy BSR) data and converted to CSR. Blocks are split
into one contiguous range per thread (numba.get_num_threads() Python threads running GIL-free
numba kernels); each thread owns a copy of the data, summed at the end: no write races, work
linear in the number of points, O(n_q²) per point for its n_q ≈ 50–90 nodes.
"""
from __future__ import annotations

import numpy as np
from numba import njit
from scipy.sparse import bsr_matrix

from .assembly_plan import balanced_ranges, n_threads, run_threads
from .point_kernels import (
    gradient_hessian_point,
    kinematics_point,
    strain_jacobians_point,
    voigt_elasticity_point,
)

MODE_LINEAR = 0
MODE_TANGENT = 1


@njit(cache=True, nogil=True)
def _linear_factors(q, indptr, basis, reference, w, D, h):
    """(Lf, Rf), each (n, 3, 6): K_ab[i, j] = Σ_s Lf[a, i, s] Rf[b, j, s] (Paper 1 App. C).

    Lf[a] = (M_a; B_a)ᵀ and Rf[b] = w (h D M_b; h³/12 D B_b)ᵀ.
    """
    t0 = indptr[q]
    n = indptr[q + 1] - t0
    Je = np.empty((3, 15))
    Jk = np.empty((3, 15))
    strain_jacobians_point(reference[q], Je, Jk)
    hb = h ** 3 / 12.0
    Lf = np.zeros((n, 3, 6))
    Rf = np.zeros((n, 3, 6))
    for a in range(n):
        for kk in range(5):
            p = basis[t0 + a, kk + 1]
            for r in range(3):
                for i in range(3):
                    Lf[a, i, r] += p * Je[r, 3 * kk + i]
                    Lf[a, i, 3 + r] += p * Jk[r, 3 * kk + i]
        for r in range(3):
            for s in range(3):
                for i in range(3):
                    Rf[a, i, r] += w * h * D[r, s] * Lf[a, i, s]
                    Rf[a, i, 3 + r] += w * hb * D[r, s] * Lf[a, i, 3 + s]
    return Lf, Rf


@njit(cache=True, nogil=True)
def _tangent_factor(q, indptr, indices, basis, reference, U, w, D, h):
    """G (n, 3, 5, 3): K_ab[i, j] = Σ_l G[a, i, l, j] p_b,l, G = w Σ_k p_a,k ∂²w/∂y_(k,i)∂y_(l,j)."""
    t0 = indptr[q]
    n = indptr[q + 1] - t0
    y = np.empty((5, 3))
    g = np.empty(15)
    H = np.empty((15, 15))
    kinematics_point(q, indptr, indices, basis, reference, U, y)
    gradient_hessian_point(y, reference[q], D, h, g, H, True)
    G = np.zeros((n, 3, 5, 3))
    for a in range(n):
        for kk in range(5):
            pw = w * basis[t0 + a, kk + 1]
            for i in range(3):
                for ll in range(5):
                    for j in range(3):
                        G[a, i, ll, j] += pw * H[3 * kk + i, 3 * ll + j]
    return G


@njit(cache=True, nogil=True)
def _store(Kloc, la, lb, same, blk):
    """Kloc[la, lb] += blk for a < b (flush adds Kloc[lb, la]ᵀ); a node repeated: blk + blkᵀ."""
    for i in range(3):
        for j in range(3):
            Kloc[la, lb, i, j] += blk[i, j] + (blk[j, i] if same else 0.0)


@njit(cache=True, nogil=True)
def _add_linear_point(Lf, Rf, loc, Kloc):
    """Pairs a ≤ b of one point: K_ab = Lf_a Rf_bᵀ, stored once (see _store)."""
    n = Lf.shape[0]
    blk = np.empty((3, 3))
    for a in range(n):
        la = loc[a]
        for b in range(a, n):
            for i in range(3):
                for j in range(3):
                    s = 0.0
                    for k in range(6):
                        s += Lf[a, i, k] * Rf[b, j, k]
                    blk[i, j] = s
            _store(Kloc, la, loc[b], b != a and loc[b] == la, blk)


@njit(cache=True, nogil=True)
def _add_tangent_point(G, basis, t0, loc, Kloc):
    """Pairs a ≤ b of one point: K_ab[i, j] = Σ_l G[a, i, l, j] p_b,l, stored once."""
    n = G.shape[0]
    blk = np.empty((3, 3))
    for a in range(n):
        la = loc[a]
        for b in range(a, n):
            blk[:, :] = 0.0
            for ll in range(5):
                c = basis[t0 + b, ll + 1]
                for i in range(3):
                    for j in range(3):
                        blk[i, j] += G[a, i, ll, j] * c
            _store(Kloc, la, loc[b], b != a and loc[b] == la, blk)


@njit(cache=True, nogil=True)
def _stiffness_blocks(mode, blk0, blk1, order, block_ptr, indptr, indices, basis, reference,
                      weights, U, E, nu, h, row_ptr, cols, n_nodes, data):
    """Add the stiffness of point blocks blk0..blk1 to the block-CSR data (nnz_blocks, 3, 3)."""
    gl = np.full(n_nodes, -1, np.int64)  # global node -> position in the block's node list
    D = np.empty((3, 3))
    for blk in range(blk0, blk1):
        count = 0
        for k in range(block_ptr[blk], block_ptr[blk + 1]):
            count += indptr[order[k] + 1] - indptr[order[k]]
        nodes = np.empty(count, np.int64)
        nL = 0
        for k in range(block_ptr[blk], block_ptr[blk + 1]):
            q = order[k]
            for t in range(indptr[q], indptr[q + 1]):
                A = indices[t]
                if gl[A] < 0:
                    gl[A] = nL
                    nodes[nL] = A
                    nL += 1
        Kloc = np.zeros((nL, nL, 3, 3))
        for k in range(block_ptr[blk], block_ptr[blk + 1]):
            q = order[k]
            voigt_elasticity_point(reference[q], E, nu, D)
            loc = np.empty(indptr[q + 1] - indptr[q], np.int64)
            for t in range(indptr[q], indptr[q + 1]):
                loc[t - indptr[q]] = gl[indices[t]]
            if mode == MODE_LINEAR:
                Lf, Rf = _linear_factors(q, indptr, basis, reference, weights[q], D, h)
                _add_linear_point(Lf, Rf, loc, Kloc)
            else:
                G = _tangent_factor(q, indptr, indices, basis, reference, U, weights[q], D, h)
                _add_tangent_point(G, basis, indptr[q], loc, Kloc)
        for i in range(nL):  # flush: K_ij = Kloc_ij + Kloc_jiᵀ (i ≠ j), K_ii = Kloc_ii
            A = nodes[i]
            for p in range(row_ptr[A], row_ptr[A + 1]):
                j = gl[cols[p]]
                if j >= 0:
                    for a in range(3):
                        for b in range(3):
                            data[p, a, b] += Kloc[i, j, a, b]
                            if j != i:
                                data[p, a, b] += Kloc[j, i, b, a]
        for i in range(nL):
            gl[nodes[i]] = -1


def assemble_stiffness(mode: int, q, mat, U: np.ndarray):
    """scipy CSR (3N, 3N): mode 0 = linear K (App. C), mode 1 = tangent ∂²W/∂U² at U."""
    plan = q.assembly_plan()
    args = (plan.order, plan.block_ptr, q.indptr, q.indices, q.basis, q.reference, q.weights, U,
            float(mat.young_modulus), float(mat.poisson_ratio), float(mat.thickness),
            plan.row_ptr, plan.cols, np.int64(q.n_nodes))

    def work(b0, b1):
        data = np.zeros((len(plan.cols), 3, 3))
        _stiffness_blocks(np.int64(mode), b0, b1, *args, data)
        return data

    parts = run_threads(work, [tuple(r) for r in plan.thread_bounds])
    data = parts[0]
    for extra in parts[1:]:
        data += extra
    N = q.n_nodes
    K = bsr_matrix((data, plan.cols, plan.row_ptr), shape=(3 * N, 3 * N), blocksize=(3, 3))
    return K.tocsr()


@njit(cache=True, nogil=True)
def _forces_range(q0, q1, indptr, indices, basis, reference, weights, U, E, nu, h, dens, f,
                  want_forces):
    """dens[q] = (w_m, w_b) and f[a] += w_q Σ_k p_a,k ∂w/∂y_k for points q0..q1."""
    y = np.empty((5, 3))
    D = np.empty((3, 3))
    g = np.empty(15)
    H = np.empty((1, 1))
    for q in range(q0, q1):
        kinematics_point(q, indptr, indices, basis, reference, U, y)
        voigt_elasticity_point(reference[q], E, nu, D)
        wm, wb = gradient_hessian_point(y, reference[q], D, h, g, H, False)
        dens[q, 0] = wm
        dens[q, 1] = wb
        if want_forces:
            w = weights[q]
            for t in range(indptr[q], indptr[q + 1]):
                a = indices[t]
                for kk in range(5):
                    p = w * basis[t, kk + 1]
                    for i in range(3):
                        f[a, i] += p * g[3 * kk + i]


def densities_and_forces(q, mat, U: np.ndarray, want_forces: bool):
    """((m, 2) membrane/bending energy per reference area, (N, 3) ∂W/∂U or zeros)."""
    dens = np.zeros((q.n_points, 2))
    ranges = balanced_ranges(np.diff(q.indptr).astype(float), n_threads(q.n_points))

    def work(q0, q1):
        f = np.zeros((q.n_nodes, 3))
        _forces_range(q0, q1, q.indptr, q.indices, q.basis, q.reference, q.weights, U,
                      float(mat.young_modulus), float(mat.poisson_ratio), float(mat.thickness),
                      dens, f, bool(want_forces))
        return f

    parts = run_threads(work, ranges)
    f = parts[0]
    for extra in parts[1:]:
        f += extra
    return dens, f
