"""Fused d = 2 Hessians of the LME basis functions (the hot case of lme_kernels.derivatives).

Same formula as the general kernel (module docstring of :mod:`.lme_kernels`), for one point:

    H p_a = p_a [ g_a⊗g_a - G + 2(β̄ - β_a) I - Σ_k (J⁻¹y_a)_k S_k ],
    G = Σ_c p_c g_c⊗g_c,   S_k = Σ_c p_c (y_c)_k (g_c⊗g_c - 2 β_c I),

but with all sums in one pass over the support nodes and the Hessians written in a second one
(the general kernel makes ~25 passes for d = 2).
"""
from __future__ import annotations

import numba as nb

from .small_math import FAST as _FAST


@nb.njit(cache=True, fastmath=_FAST)
def hessians_2d(yT, beta, p, gT, Jinv, bbar, k, lo, hess):
    """H p_a into hess[lo + a] (2, 2) for a < k; yT, gT (2, ≥k) rows y_a and g_a, Jinv (2, 2)."""
    y0, y1 = yT[0], yT[1]
    g0, g1 = gT[0], gT[1]
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
    i00, i01, i10, i11 = Jinv[0, 0], Jinv[0, 1], Jinv[1, 0], Jinv[1, 1]
    for a in range(k):
        j0 = i00 * y0[a] + i01 * y1[a]
        j1 = i10 * y0[a] + i11 * y1[a]
        diag = 2.0 * (bbar - beta[a])
        pa = p[a]
        h00 = pa * (g0[a] * g0[a] - G00 + diag - j0 * S000 - j1 * S100)
        h01 = pa * (g0[a] * g1[a] - G01 - j0 * S001 - j1 * S101)
        h11 = pa * (g1[a] * g1[a] - G11 + diag - j0 * S011 - j1 * S111)
        hess[lo + a, 0, 0] = h00
        hess[lo + a, 0, 1] = h01
        hess[lo + a, 1, 0] = h01
        hess[lo + a, 1, 1] = h11

