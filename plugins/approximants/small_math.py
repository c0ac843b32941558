"""Small numba helpers for the approximant kernels: d×d Cholesky solves, a vectorisable exp."""
from __future__ import annotations

import numba as nb
import numpy as np

#: fast-math flags that keep NaN/inf semantics (the kernels test for divergence)
FAST = {"contract", "reassoc", "arcp", "nsz"}

@nb.njit(cache=True, inline="always")
def cholesky(A, L):
    """Lower Cholesky factor of the small SPD matrix A into L; False if not positive definite."""
    d = A.shape[0]
    scale = 0.0
    for i in range(d):
        scale = max(scale, abs(A[i, i]))
    for j in range(d):
        s = A[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not s > 1e-14 * scale or scale == 0.0:
            return False
        L[j, j] = np.sqrt(s)
        for i in range(j + 1, d):
            t = A[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t / L[j, j]
        for i in range(j):
            L[i, j] = 0.0
    return True


@nb.njit(cache=True, inline="always")
def cholesky_solve(L, b, out):
    """Solve L Lᵀ out = b."""
    d = L.shape[0]
    for i in range(d):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * out[k]
        out[i] = s / L[i, i]
    for i in range(d - 1, -1, -1):
        s = out[i]
        for k in range(i + 1, d):
            s -= L[k, i] * out[k]
        out[i] = s / L[i, i]


_LOG2E = 1.4426950408889634
_LN2_HI = 0.693147180369123816490
_LN2_LO = 1.90821492927058770002e-10


#: 1.5 * 2**52: adding it to an integer-valued float n (|n| < 2**51) puts n in the low bits
_SHIFTER = 6755399441055744.0
_SHIFTER_BITS = 0x4338000000000000


#: fused multiply-add allowed, but no reassociation (it would undo the shifter trick)
CONTRACT = {"contract", "arcp", "nsz"}


@nb.njit(cache=True, fastmath=CONTRACT)
def exp_shifted(x, k, shift, ib):
    """x[:k] <- exp(x[:k] - shift) in place, for x ≤ shift (x - shift < -700 gives ~1e-304).

    Cody-Waite reduction x = n ln2 + r, |r| ≤ ln2/2, degree-13 Taylor polynomial for e^r
    (truncation < 2e-16), scaling by 2^n built in the exponent bits: n + 1.5·2^52 holds n in
    its low bits, so no float → int64 conversion (which AVX2 lacks) is needed and every loop
    vectorises. Scratch ``ib`` (≥k,) int64. Relative error ~2e-15.
    """
    fb = ib[:k].view(np.float64)
    for a in range(k):
        t = max(x[a] - shift, -700.0)
        n = np.rint(t * _LOG2E)
        r = (t - n * _LN2_HI) - n * _LN2_LO
        q = 1.0 / 6227020800.0
        q = q * r + 1.0 / 479001600.0
        q = q * r + 1.0 / 39916800.0
        q = q * r + 1.0 / 3628800.0
        q = q * r + 1.0 / 362880.0
        q = q * r + 1.0 / 40320.0
        q = q * r + 1.0 / 5040.0
        q = q * r + 1.0 / 720.0
        q = q * r + 1.0 / 120.0
        q = q * r + 1.0 / 24.0
        q = q * r + 1.0 / 6.0
        q = q * r + 0.5
        q = q * r + 1.0
        x[a] = q * r + 1.0
        fb[a] = n + _SHIFTER
    for a in range(k):
        ib[a] = (ib[a] - (_SHIFTER_BITS - 1023)) << 52
    for a in range(k):
        x[a] *= fb[a]


@nb.njit(cache=True)
def exp_nonpositive(x, k, ib):
    """x[:k] <- exp(x[:k]) in place, for x ≤ 0 (see :func:`exp_shifted`)."""
    exp_shifted(x, k, 0.0, ib)
