"""The last Newton step of the LME dual without exponentials (a Taylor update of the weights).

Near λ* Newton converges quadratically, so the step Δ that takes |r| below the tolerance is tiny.
For it the weights need no new exponentials: exp(f_a + Δ·y_a) = exp(f_a) e^u with u = Δ·y_a,
and with |u| ≤ |Δ| max|y_a| < SMALL_EXPONENT_STEP the cubic Taylor polynomial of e^u is exact
to |u|⁴/24 < 5e-18 relative, below round-off. The result is the same p_a(λ + Δ) the full
evaluation would give, one pass of exponentials cheaper (of ~5 per point).
"""
from __future__ import annotations

import numba as nb
import numpy as np

from .small_math import FAST as _FAST

#: largest |Δ|·max_a|y_a| for which the Taylor update replaces the exponentials
SMALL_EXPONENT_STEP = 1e-4


@nb.njit(cache=True, fastmath=_FAST)
def small_step_converges(yT, k, step, p, tol):
    """Apply a tiny step to the unnormalised weights p[:k] in place: p_a e^{Δ·y_a} (Taylor).

    Returns True, with p normalised, if the residual |Σ p_a y_a| at λ + Δ is below ``tol``;
    False otherwise (p is then garbage: the caller re-evaluates it from scratch).
    """
    d = yT.shape[0]
    for a in range(k):
        u = 0.0
        for i in range(d):
            u += step[i] * yT[i, a]
        p[a] *= 1.0 + u * (1.0 + u * (0.5 + u * (1.0 / 6.0)))
    z = 0.0
    for a in range(k):
        z += p[a]
    inv = 1.0 / z
    rn = 0.0
    for i in range(d):
        yi = yT[i]
        s = 0.0
        for a in range(k):
            s += p[a] * yi[a]
        rn += (s * inv) ** 2
    if not np.sqrt(rn) < tol:
        return False
    for a in range(k):
        p[a] *= inv
    return True
