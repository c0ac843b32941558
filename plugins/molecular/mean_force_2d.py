"""Two-dimensional free energies from a mean-force field: the CZAR gradient on a grid and its
integration by a least-squares (Poisson) solve (kJ/mol; CV units per axis).

CZAR in d dimensions (Lesage et al., J. Phys. Chem. B 121 (2017) 3676, Eq. 12, per axis):

    ∂A/∂z_a = −kT ∂ln ρ̃/∂z_a + k_a (⟨λ_a⟩_z − z_a).

Integration: A on the valid cells minimises Σ over neighbouring valid pairs of
(ΔA/h_a − ½(g_a + g_a'))², i.e. the discrete Poisson equation ∇²A = ∇·g with natural
(Neumann) conditions on the border of the sampled region (the usual way to integrate an ABF
gradient field in 2-D; Hénin et al., J. Chem. Theory Comput. 6 (2010) 35), solved by sparse
least squares; the gauge is min A = 0.
"""
from __future__ import annotations

import numpy as np


def czar_gradient_2d(count, lam_minus_z_sum, widths, k, kT, periodic=(False, False),
                     min_count=20):
    """(n1, n2, 2) gradient of A per cell from the counts (n1, n2) of z and the sums of
    λ − z (n1, n2, 2); NaN where the cell or a neighbour along an axis has < ``min_count``."""
    n = np.asarray(count, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        lnr = np.where(n > 0, np.log(n), np.nan)
        mean = np.where(n[..., None] > 0, lam_minus_z_sum / n[..., None], np.nan)
    out = np.full(n.shape + (2,), np.nan)
    k = np.broadcast_to(np.asarray(k, dtype=float), (2,))
    for a in range(2):
        if periodic[a]:
            dln = (np.roll(lnr, -1, a) - np.roll(lnr, 1, a)) / (2 * widths[a])
            ok = (n >= min_count) & (np.roll(n, 1, a) >= min_count) & \
                (np.roll(n, -1, a) >= min_count)
        else:
            dln = np.gradient(lnr, widths[a], axis=a, edge_order=2) if n.shape[a] > 2 else \
                np.gradient(lnr, widths[a], axis=a)
            ok = n >= min_count
            lo = [slice(None)] * 2
            hi = [slice(None)] * 2
            mid = [slice(None)] * 2
            lo[a], hi[a], mid[a] = slice(None, -2), slice(2, None), slice(1, -1)
            ok[tuple(mid)] &= (n[tuple(lo)] >= min_count) & (n[tuple(hi)] >= min_count)
        out[..., a] = np.where(ok, -kT * dln + k[a] * mean[..., a], np.nan)
    return out


def integrate_2d(grad, widths, periodic=(False, False)):
    """A (n1, n2) in kJ/mol, min 0, NaN outside the largest connected set of valid cells,
    from the gradient field (n1, n2, 2) by least squares over neighbouring valid pairs."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.sparse.linalg import lsqr

    g = np.asarray(grad, dtype=float)
    n1, n2 = g.shape[:2]
    valid = np.all(np.isfinite(g), axis=-1)
    idx = -np.ones((n1, n2), dtype=int)
    idx[valid] = np.arange(valid.sum())
    rows, cols, vals, rhs = [], [], [], []
    for a in range(2):
        for i in range(n1):
            for j in range(n2):
                if not valid[i, j]:
                    continue
                ii, jj = (i + 1, j) if a == 0 else (i, j + 1)
                size = n1 if a == 0 else n2
                nxt = ii if a == 0 else jj
                if nxt == size:
                    if not periodic[a]:
                        continue
                    ii, jj = (0, j) if a == 0 else (i, 0)
                if not valid[ii, jj]:
                    continue
                r = len(rhs)
                rows += [r, r]
                cols += [idx[ii, jj], idx[i, j]]
                vals += [1.0 / widths[a], -1.0 / widths[a]]
                rhs.append(0.5 * (g[i, j, a] + g[ii, jj, a]))
    A = np.full((n1, n2), np.nan)
    m = int(valid.sum())
    if m == 0 or not rhs:
        return A
    M = coo_matrix((vals, (rows, cols)), shape=(len(rhs), m)).tocsr()
    adj = (M.T @ M) != 0
    _, labels = connected_components(adj, directed=False)
    keep = labels == np.argmax(np.bincount(labels))
    # a pair lies within one component: keep the rows of the largest one
    rows_kept = np.asarray(abs(M[:, ~keep]).sum(axis=1)).ravel() == 0
    sol = lsqr(M[rows_kept][:, keep], np.asarray(rhs)[rows_kept], atol=1e-12, btol=1e-12,
               iter_lim=20 * m)[0]
    flat = np.full(m, np.nan)
    flat[keep] = sol
    A[valid] = flat
    return A - np.nanmin(A)
