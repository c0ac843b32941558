"""Numba kernels of the kit's assembler: jets, residual scatter and tangent blocks.

With the jet tables of :class:`.fields.FieldLayout` (``col[r]`` the basis column and
``dof[r]`` the in-block DOF of jet entry r) and point weights w_q (thesis Eq. 14):

    jet_q[r]         = Σ_a p_a,col[r](ξ_q) U[a, dof[r]]
    f[a, I]         += w_q Σ_{r: dof[r]=I} p_a,col[r] g_q[r]                 (residual)
    K_ab[I, J]      += w_q Σ_{r: dof[r]=I} Σ_{s: dof[s]=J} p_a,col[r] H_q[r, s] p_b,col[s]

evaluated, for the tangent, through G[a, I, s] = w_q Σ_{r: dof[r]=I} p_a,col[r] H_q[r, s],
so a node pair costs B·n_jet operations; with one field the products of a batch of
neighbouring points are one matrix product (BLAS, all node pairs of the batch). The tangent
of a point block is accumulated in a dense (|L|, |L|, B, B) array over the block's node set
L (several fields: pairs a ≤ b, K being symmetric) and flushed once into the block-CSR data
of the plan (:mod:`.assembly_plan`).
"""
from __future__ import annotations

import numpy as np
from numba import literally, njit

from .assembly_plan import BATCH_POINTS, grow_batch


@njit(cache=True, nogil=True)
def jets_at(points, indptr, indices, basis, U, col, dof, out):
    """out[k] = jet at point points[k] (see module doc); out (len(points), n_jet)."""
    n_jet = len(col)
    for k in range(len(points)):
        q = points[k]
        for r in range(n_jet):
            out[k, r] = 0.0
        for t in range(indptr[q], indptr[q + 1]):
            a = indices[t]
            for r in range(n_jet):
                out[k, r] += basis[t, col[r]] * U[a, dof[r]]


@njit(cache=True, nogil=True)
def scatter_gradient(points, indptr, indices, basis, weights, g, col, dof, f):
    """f[a, dof[r]] += w_q p_a,col[r] g[k, r] for the points points[k]."""
    n_jet = len(col)
    for k in range(len(points)):
        q = points[k]
        w = weights[q]
        for t in range(indptr[q], indptr[q + 1]):
            a = indices[t]
            for r in range(n_jet):
                f[a, dof[r]] += w * basis[t, col[r]] * g[k, r]


@njit(cache=True, nogil=True)
def tangent_blocks(blk0, blk1, order, block_ptr, first, indptr, indices, basis, weights, H,
                   col, dof, fcol, fncol, fcomp, foff, fjet, B, n_jet, row_ptr, cols, n_nodes,
                   data):
    """Add the tangent of point blocks blk0..blk1 to the block-CSR ``data`` (nnz, B, B).

    H[k] is the energy Hessian at point order[first + k]; ``col``/``dof`` are the jet tables
    and the per-field tables (first basis column, number of columns, components, DOF offset,
    jet offset) the same layout by field (:class:`.fields.FieldLayout`). B and the jet size
    (Python ints) are compile-time constants of the specialisation (numba ``literally``), so the small
    loops over components unroll.
    """
    _tangent_blocks(blk0, blk1, order, block_ptr, first, indptr, indices, basis, weights, H,
                    col, dof, fcol, fncol, fcomp, foff, fjet, literally(B),
                    literally(n_jet), row_ptr, cols, n_nodes, data)


@njit(cache=True, nogil=True)
def _tangent_blocks(blk0, blk1, order, block_ptr, first, indptr, indices, basis, weights, H,
                    col, dof, fcol, fncol, fcomp, foff, fjet, B, n_jet, row_ptr, cols, n_nodes,
                    data):
    nf = len(fcol)
    gl = np.full(n_nodes, -1, np.int64)  # global node -> position in the block's node list
    sub = np.full(n_nodes, -1, np.int64)     # global node -> position in a batch (grow_batch)
    snodes = np.empty(n_nodes, np.int64)
    # every array of the loops below is a view of buffers allocated here once: a heap
    # allocation per batch and block was 2x slower where freed memory goes back to the OS
    # at once (Dask's workers set MALLOC_TRIM_THRESHOLD_=65536: each batch's arrays were
    # fresh pages, zeroed by the kernel)
    kbuf = np.empty(0)
    nmax = 1
    for k in range(block_ptr[blk0], block_ptr[blk1]):
        nmax = max(nmax, indptr[order[k] + 1] - indptr[order[k]])
    scratch = _batch_scratch(nmax if nf == 1 else 0, fncol[0], B)   # (one field only)
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
        size = nL * nL * B * B
        if size > kbuf.size:
            kbuf = np.empty(size)
        kbuf[:size] = 0.0
        Kloc = kbuf[:size].reshape((nL, nL, B, B))
        blkv = np.empty((B, B))
        if nf == 1:
            _one_field_batches(block_ptr[blk], block_ptr[blk + 1], first, order, indptr,
                               indices, basis, weights, H, fcol[0], fncol[0], B, gl, sub,
                               snodes, Kloc, scratch)
        else:
            for k in range(block_ptr[blk], block_ptr[blk + 1]):
                q = order[k]
                h = k - first
                t0 = indptr[q]
                n = indptr[q + 1] - t0
                w = weights[q]
                G = np.zeros((n, B, n_jet))
                for a in range(n):
                    for r in range(n_jet):
                        pw = w * basis[t0 + a, col[r]]
                        I = dof[r]
                        for s in range(n_jet):
                            G[a, I, s] += pw * H[h, r, s]
                for a in range(n):
                    la = gl[indices[t0 + a]]
                    for b in range(a, n):
                        lb = gl[indices[t0 + b]]
                        blkv[:, :] = 0.0
                        for s in range(n_jet):
                            c = basis[t0 + b, col[s]]
                            J = dof[s]
                            for I in range(B):
                                blkv[I, J] += G[a, I, s] * c
                        same = b != a and lb == la
                        for I in range(B):
                            for J in range(B):
                                Kloc[la, lb, I, J] += blkv[I, J] + (blkv[J, I] if same else 0.0)
        for i in range(nL):  # flush (several fields: K_ij = Kloc_ij + Kloc_jiᵀ, i ≠ j)
            A = nodes[i]
            for p in range(row_ptr[A], row_ptr[A + 1]):
                j = gl[cols[p]]
                if j >= 0:
                    for I in range(B):
                        for J in range(B):
                            data[p, I, J] += Kloc[i, j, I, J]
                            if j != i and nf > 1:  # several fields: pairs a ≤ b only
                                data[p, I, J] += Kloc[j, i, J, I]
        for i in range(nL):
            gl[nodes[i]] = -1


@njit(cache=True, nogil=True)
def _batch_scratch(nmax, nc, B):
    """Flat buffers for :func:`_one_field_batches` of points with at most ``nmax`` nodes:
    (Φ₁, Φ₂, G₁, G₂, P₁₁, P₁₂, P₂₂, Φ_q, T_q, H̃), each large enough for any batch."""
    h = ((3 * nmax) // 2 + 1) // 2      # half of the largest batch's node set
    BB = B * B
    m = nc * BATCH_POINTS
    return (np.empty(h * m), np.empty(h * m), np.empty(m * h * BB), np.empty(m * h * BB),
            np.empty(h * h * BB), np.empty(h * h * BB), np.empty(h * h * BB),
            np.empty(nmax * nc), np.empty(nmax * nc * BB), np.empty(nc * nc * BB))


@njit(cache=True, nogil=True)
def _zeroed(buf, rows, cols):
    """buf's first rows·cols entries, set to 0, as a (rows, cols) array."""
    buf[:rows * cols] = 0.0
    return buf[:rows * cols].reshape((rows, cols))


@njit(cache=True, nogil=True)
def _one_field_batches(k0, k1, first, order, indptr, indices, basis, weights, H, c0, nc, B,
                       gl, sub, snodes, Kloc, scratch):
    """Kloc += the tangent of the points order[k0:k1] of a single-field layout, in batches of
    consecutive points whose supports overlap (the plan orders points by nearest node; the
    batches are :func:`.assembly_plan.grow_batch`'s; ``sub``/``snodes`` its scratch arrays).

    For a batch S with union node set L_S, K_ab[i, j] = Σ_{q∈S} Σ_kk p_b,kk(q) G[(q, kk),
    (a, i, j)], G[(q, kk), (a, i, j)] = w_q Σ_k' p_a,k'(q) H_q[k'B + i, kk B + j]: the matrix
    product Φ_S G (BLAS) of (|L_S|, |S| nc) by (|S| nc, |L_S| B²) per batch; G's rows of a
    point are themselves one product Φ_q H̃_q. With L_S cut in halves (1, 2), Φ_S G is
    three products (Φ₁G₁, Φ₁G₂, Φ₂G₂): the fourth block is the transpose of Φ₁G₂ (K_ab =
    K_baᵀ, H symmetric), 3/4 of the multiply-adds (pull-out, 110 nodes and 31 points a
    batch: 0.56 ms against 0.67 ms per batch on one BLAS thread; the whole tangent 1.24–1.34 s
    → 1.18–1.20 s, the other half of it being the scatter into G and K_loc). A batch grows
    while its union stays within 3/2 of the largest support (so Φ_S is mostly nonzero) and
    it holds at most 32 points (hemisphere, 90 nodes per point: 2.5x faster than one product
    per point). Every array is a view of ``scratch`` (:func:`_batch_scratch`), so a batch
    allocates nothing.
    """
    nmax = 1
    for k in range(k0, k1):
        nmax = max(nmax, indptr[order[k] + 1] - indptr[order[k]])
    cap = (3 * nmax) // 2
    BB = B * B
    sPhi1, sPhi2, sG1, sG2, sP11, sP12, sP22, sPhi, sT, sHr = scratch
    Hr = sHr[:nc * nc * BB].reshape((nc, nc * BB))
    k = k0
    while k < k1:
        s0 = k
        k, nS = grow_batch(order, k, k1, indptr, indices, cap, sub, snodes)
        mS = k - s0
        h = (nS + 1) // 2     # the batch's nodes in two halves: K_ab for b ≥ h, a < h is
        h2 = nS - h           # K_baᵀ (H symmetric), so three products instead of four
        Phi1 = _zeroed(sPhi1, h, nc * mS)
        Phi2 = _zeroed(sPhi2, h2, nc * mS)
        G1 = _zeroed(sG1, nc * mS, h * BB)
        G2 = _zeroed(sG2, nc * mS, h2 * BB)
        for j in range(mS):
            q = order[s0 + j]
            hq = s0 + j - first
            t0 = indptr[q]
            n = indptr[q + 1] - t0
            w = weights[q]
            Phi = sPhi[:n * nc].reshape((n, nc))
            for a in range(n):
                for kk in range(nc):
                    Phi[a, kk] = basis[t0 + a, c0 + kk]
            for kp in range(nc):
                for i in range(B):
                    for kk in range(nc):
                        for jj in range(B):
                            Hr[kp, kk * BB + i * B + jj] = w * H[hq, kp * B + i, kk * B + jj]
            T = sT[:n * nc * BB].reshape((n, nc * BB))
            np.dot(Phi, Hr, T)  # T[a, (kk, i, j)] = G[(q, kk), (a, i, j)]
            for a in range(n):
                sa = sub[indices[t0 + a]]
                for kk in range(nc):
                    if sa < h:
                        Phi1[sa, j * nc + kk] += Phi[a, kk]
                        for r in range(BB):
                            G1[j * nc + kk, sa * BB + r] += T[a, kk * BB + r]
                    else:
                        Phi2[sa - h, j * nc + kk] += Phi[a, kk]
                        for r in range(BB):
                            G2[j * nc + kk, (sa - h) * BB + r] += T[a, kk * BB + r]
        P11 = sP11[:h * h * BB].reshape((h, h * BB))
        P12 = sP12[:h * h2 * BB].reshape((h, h2 * BB))
        P22 = sP22[:h2 * h2 * BB].reshape((h2, h2 * BB))
        np.dot(Phi1, G1, P11)  # P11[b, (a, i, j)] = K_ab[i, j], a, b < h
        if h2 > 0:
            np.dot(Phi1, G2, P12)  # P12[b, (a − h, i, j)] = K_ab[i, j], b < h ≤ a
            np.dot(Phi2, G2, P22)  # P22[b − h, (a − h, i, j)] = K_ab[i, j], a, b ≥ h
        for a in range(nS):
            la = gl[snodes[a]]
            for b in range(nS):
                lb = gl[snodes[b]]
                for i in range(B):
                    for j in range(B):
                        if b < h:
                            v = P11[b, a * BB + i * B + j] if a < h else \
                                P12[b, (a - h) * BB + i * B + j]
                        elif a >= h:
                            v = P22[b - h, (a - h) * BB + i * B + j]
                        else:
                            v = P12[a, (b - h) * BB + j * B + i]   # K_ab = K_baᵀ
                        Kloc[la, lb, i, j] += v
        sub[snodes[:nS]] = -1
