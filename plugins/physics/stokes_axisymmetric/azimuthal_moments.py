"""Azimuthal moments L_{n,m}(a, b) = ∫_0^{2π} (1 − cos φ)^n (a − b cos φ)^{−m/2} dφ.

Integrating the free-space Stokeslet and stresslet over a ring of radius r at a field point at
distance r₀ from the axis reduces to these moments with

    a = r² + r₀² + (z − z₀)²,   b = 2 r r₀,   a − b cos φ = |x₀ − y(φ)|²

(Pozrikidis 1992, §2.4 and §6.1; here derived from scratch). With the parameter of the
complete elliptic integrals m = k² = 2b/(a + b) (``scipy.special.ellipk/ellipe`` take m),
the moments without powers of cos φ, L_{0,m} = ∫ ρ^{−m} dφ, are

    L_{0,−1} = 4 √(a+b) E(m),          L_{0,1} = 4 K(m) / √(a+b),
    L_{0,3}  = 4 E(m) / ((a−b) √(a+b)),
    L_{0,5}  = 8 / (3 (a−b) (a+b)^{3/2}) · (2a E(m)/(a−b) − K(m)/2)

(L_{0,5} = −(2/3) ∂L_{0,3}/∂a, with dE/dm = (E − K)/(2m) and
dK/dm = (E − (1−m)K)/(2m(1−m))). Powers of u = 1 − cos φ follow from
u = (ρ² − (a − b))/b:

    L_{n,m} = (L_{n−1,m−2} − (a − b) L_{n−1,m}) / b.

Powers of u rather than of cos φ keep every kernel accurate at the self point, where
a − b → 0: there L_{0,5} ~ (a−b)^{−2} while the stresslet's numerator vanishes like
(a − b) + b u; written in u the small factors are formed from coordinate differences and no
two large moments cancel (in powers of cos φ the double layer lost all digits within 1e-5
of an element's length of the collocation point). The recurrence loses digits as
b/a → 0 (the ring or the field point near the axis, where the moments tend to their axis
limits 2π⟨u^n⟩ a^{−m/2}). Where m < ``M_SWITCH`` the
integrand is analytic in a strip of half-width arccosh(a/b) and the periodic trapezoidal rule
with N points converges geometrically (error ~ q^N, q = (a − √(a²−b²))/b: q < 0.18 at
m < 0.5 with N = 24, q < 0.027 at m < 0.1 with N = 12, both below 1e-17): that branch is
used there, the closed forms elsewhere, including the logarithmically singular limit m → 1
of the self-element.
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange
from scipy.special import ellipe, ellipkm1

#: below this elliptic parameter m the trapezoidal rule is used (module doc)
M_SWITCH = 0.5
#: points of the periodic trapezoidal rule in φ for m < M_SWITCH, and for m < M_FAR
N_TRAPEZOID = 24
M_FAR, N_FAR = 0.1, 12
#: the (n, m) pairs returned, in this order (columns of :func:`azimuthal_moments`)
PAIRS = ((0, 1), (1, 1), (0, 3), (1, 3), (2, 3), (0, 5), (1, 5), (2, 5), (3, 5))
INDEX = {p: k for k, p in enumerate(PAIRS)}


def _closed_form(a: np.ndarray, b: np.ndarray, amb: np.ndarray) -> np.ndarray:
    apb = a + b
    p = amb / apb                                  # 1 − m, accurate near the ring
    K, E = ellipkm1(p), ellipe(1.0 - p)
    s = np.sqrt(apb)
    I = np.empty(a.shape + (len(PAIRS),))
    Im1 = 4.0 * s * E
    I01 = 4.0 * K / s
    I03 = 4.0 * E / (amb * s)
    I05 = 8.0 / (3.0 * amb * apb * s) * (2.0 * a * E / amb - 0.5 * K)
    I11 = (Im1 - amb * I01) / b
    I13 = (I01 - amb * I03) / b
    I23 = (I11 - amb * I13) / b
    I15 = (I03 - amb * I05) / b
    I25 = (I13 - amb * I15) / b
    I35 = (I23 - amb * I25) / b
    for key, val in (((0, 1), I01), ((1, 1), I11), ((0, 3), I03), ((1, 3), I13),
                     ((2, 3), I23), ((0, 5), I05), ((1, 5), I15), ((2, 5), I25),
                     ((3, 5), I35)):
        I[..., INDEX[key]] = val
    return I


@njit(cache=True, parallel=True)
def _trapezoid_kernel(a, b, c, out):
    """out[i, k] = (2π/n) Σ_j u_j^{n_k} ρ_ij^{−m_k}, ρ_ij² = a_i − b_i c_j, u_j = 1 − c_j:
    the periodic trapezoidal rule on the n angles with cosines ``c``, columns as ``PAIRS``
    ((0,1), (1,1), (0,3), (1,3), (2,3), (0,5), (1,5), (2,5), (3,5))."""
    n = c.shape[0]
    w = 2.0 * np.pi / n
    for i in prange(a.shape[0]):
        s01 = s11 = s03 = s13 = s23 = s05 = s15 = s25 = s35 = 0.0
        for j in range(n):
            u = 1.0 - c[j]
            inv = 1.0 / np.sqrt(a[i] - b[i] * c[j])
            i3 = inv * inv * inv
            i5 = i3 * inv * inv
            uu = u * u
            s01 += inv
            s11 += u * inv
            s03 += i3
            s13 += u * i3
            s23 += uu * i3
            s05 += i5
            s15 += u * i5
            s25 += uu * i5
            s35 += uu * u * i5
        out[i, 0], out[i, 1], out[i, 2] = w * s01, w * s11, w * s03
        out[i, 3], out[i, 4], out[i, 5] = w * s13, w * s23, w * s05
        out[i, 6], out[i, 7], out[i, 8] = w * s15, w * s25, w * s35


def _trapezoid(a: np.ndarray, b: np.ndarray, n: int = N_TRAPEZOID) -> np.ndarray:
    """The moments of ``PAIRS`` for 1-d a, b by the n-point periodic trapezoidal rule at
    φ_j = (j + ½) 2π/n (module doc), shape (len(a), 9)."""
    c = np.cos((np.arange(n) + 0.5) * (2.0 * np.pi / n))
    out = np.empty((len(a), len(PAIRS)))
    _trapezoid_kernel(np.ascontiguousarray(a, dtype=np.float64),
                      np.ascontiguousarray(b, dtype=np.float64), c, out)
    return out


def azimuthal_moments(a, b, amb=None) -> np.ndarray:
    """L_{n,m}(a, b) for the (n, m) of ``PAIRS``, shape a.shape + (9,); a > b ≥ 0 (length²).

    ``amb``: a − b, best given as (r − r₀)² + (z − z₀)² (a − b computed by subtraction
    loses all its digits at the self point). Units: length^(−m). Closed forms with K, E
    where m = 2b/(a+b) ≥ ``M_SWITCH`` (K from 1 − m by ``ellipkm1``), the periodic
    trapezoidal rule below it (module doc)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    amb = a - b if amb is None else np.asarray(amb, dtype=np.float64)
    a, b, amb = np.broadcast_arrays(a, b, amb)
    m = 2.0 * b / (a + b)
    out = np.empty(a.shape + (len(PAIRS),))
    near = m >= M_SWITCH
    if near.any():
        out[near] = _closed_form(a[near], b[near], amb[near])
    for sel, n in ((~near & (m >= M_FAR), N_TRAPEZOID), (m < M_FAR, N_FAR)):
        if sel.any():
            out[sel] = _trapezoid(a[sel], b[sel], n)
    return out
