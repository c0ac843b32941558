"""Per-quadrature-point Kirchhoff–Love kinematics: strains, energy density, gradient, Hessian.

Kinematic variables at a point: y = (x_,1, x_,2, x_,11, x_,12, x_,22), flattened to 15 entries
y[3k + i] (k = 0..4 the derivative, i the Cartesian component). Reference Y likewise.
(Thesis §4.2, Paper 1 §3.1 Eq. 5–8 and App. B; Paper 2 §2 for the nonlinear case.)

    a_αβ = x_,α·x_,β,   v = x_,1 × x_,2,   j = |v|,   n = v/j,   b_αβ = x_,αβ·n,
    e = (ε_11, ε_22, 2ε_12),  ε_αβ = ½(a_αβ − A_αβ)         (Green membrane strain)
    k = (κ_11, κ_22, 2κ_12),  κ_αβ = B_αβ − b_αβ            (bending strain)
    w(y) = ½ h eᵀ D e + ½ h³/12 kᵀ D k                      (energy per reference area)

D = Voigt elasticity built from the reference inverse metric (see material.py).
Derivatives of b = c·v/j (c = x_,αβ) used for the gradient and the Hessian:

    ∂b/∂c = n,   ∂b/∂v = r = (c − (c·n) n)/j,
    ∂²b/∂c∂v = (I − n n)/j,
    ∂²b/∂v² = [−c vᵀ − v cᵀ − (c·v) I + 3 (c·v) n nᵀ]/j³,
    dv = dx_,1 × x_,2 + x_,1 × dx_,2 (so ∂v/∂x_,1 = −[x_,2]×, ∂v/∂x_,2 = [x_,1]×),
    d²v = 2 dx_,1 × dx_,2 (contributes the block ∂²b/∂x_,1∂x_,2 ∋ −[r]×).

At y = Y the strain Jacobians ∂e/∂y, ∂k/∂y chained with the basis derivatives are the membrane
and bending strain–displacement matrices M_a, B_a of Paper 1 App. C.
"""
from __future__ import annotations

import numpy as np
from numba import njit

VOIGT_FACTOR = np.array([1.0, 1.0, 2.0])
CURV_SLOT = np.array([2, 4, 3])  # Voigt component c uses x_,11 / x_,22 / x_,12 (y-block k)


@njit(cache=True, nogil=True)
def contravariant_metric(Y):
    """G (2, 2) = (a_αβ)⁻¹, the inverse of the metric a_αβ = Y_α · Y_β of the tangents Y[0:2]."""
    a00 = Y[0, 0] * Y[0, 0] + Y[0, 1] * Y[0, 1] + Y[0, 2] * Y[0, 2]
    a11 = Y[1, 0] * Y[1, 0] + Y[1, 1] * Y[1, 1] + Y[1, 2] * Y[1, 2]
    a01 = Y[0, 0] * Y[1, 0] + Y[0, 1] * Y[1, 1] + Y[0, 2] * Y[1, 2]
    det = a00 * a11 - a01 * a01
    G = np.empty((2, 2))
    G[0, 0] = a11 / det
    G[1, 1] = a00 / det
    G[0, 1] = -a01 / det
    G[1, 0] = -a01 / det
    return G


@njit(cache=True, nogil=True)
def voigt_elasticity_point(Y, E, nu, D):
    """D (3, 3) at one point from the reference tangents Y[0:2] (units of E / chart length⁴)."""
    G = contravariant_metric(Y)
    pa = (0, 1, 0)
    pb = (0, 1, 1)
    s = E / (1.0 - nu * nu)
    for I in range(3):
        for J in range(3):
            a, b, c, d = pa[I], pb[I], pa[J], pb[J]
            D[I, J] = s * (nu * G[a, b] * G[c, d]
                           + 0.5 * (1.0 - nu) * (G[a, c] * G[b, d] + G[a, d] * G[b, c]))


@njit(cache=True, nogil=True)
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True, nogil=True)
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, nogil=True)
def _normal(y):
    """(v, j, n) of the tangents y[0], y[1]."""
    v = np.empty(3)
    _cross(y[0], y[1], v)
    j = np.sqrt(_dot(v, v))
    return v, j, v / j


@njit(cache=True, nogil=True)
def strains_point(y, Y, e, k):
    """Membrane e and bending k Voigt strains (dimensionless / 1/length in chart units)."""
    e[0] = 0.5 * (_dot(y[0], y[0]) - _dot(Y[0], Y[0]))
    e[1] = 0.5 * (_dot(y[1], y[1]) - _dot(Y[1], Y[1]))
    e[2] = _dot(y[0], y[1]) - _dot(Y[0], Y[1])
    _, _, n = _normal(y)
    _, _, N = _normal(Y)
    for c in range(3):
        s = CURV_SLOT[c]
        k[c] = VOIGT_FACTOR[c] * (_dot(Y[s], N) - _dot(y[s], n))


@njit(cache=True, nogil=True)
def energy_point(y, Y, D, h):
    """(membrane, bending) energy per reference area: ½h eᵀDe, ½h³/12 kᵀDk."""
    e = np.empty(3)
    k = np.empty(3)
    strains_point(y, Y, e, k)
    wm = 0.0
    wb = 0.0
    for I in range(3):
        for J in range(3):
            wm += e[I] * D[I, J] * e[J]
            wb += k[I] * D[I, J] * k[J]
    return 0.5 * h * wm, 0.5 * h ** 3 / 12.0 * wb


@njit(cache=True, nogil=True)
def strain_jacobians_point(y, Je, Jk):
    """Je = ∂e/∂y and Jk = ∂k/∂y (3, 15) at the configuration y (Paper 1 App. B–C)."""
    Je[:, :] = 0.0
    Jk[:, :] = 0.0
    v, j, n = _normal(y)
    r = np.empty(3)
    t = np.empty(3)
    for i in range(3):
        Je[0, i] = y[0, i]
        Je[1, 3 + i] = y[1, i]
        Je[2, i] = y[1, i]
        Je[2, 3 + i] = y[0, i]
    for c in range(3):
        s = CURV_SLOT[c]
        f = -VOIGT_FACTOR[c]
        cn = _dot(y[s], n)
        for i in range(3):
            r[i] = (y[s, i] - cn * n[i]) / j
            Jk[c, 3 * s + i] = f * n[i]
        _cross(y[1], r, t)  # ∂b/∂x_,1 = x_,2 × r
        for i in range(3):
            Jk[c, i] = f * t[i]
        _cross(r, y[0], t)  # ∂b/∂x_,2 = r × x_,1
        for i in range(3):
            Jk[c, 3 + i] = f * t[i]


@njit(cache=True, nogil=True)
def _skew(a, S):
    """S z = a × z."""
    S[0, 0] = 0.0
    S[0, 1] = -a[2]
    S[0, 2] = a[1]
    S[1, 0] = a[2]
    S[1, 1] = 0.0
    S[1, 2] = -a[0]
    S[2, 0] = -a[1]
    S[2, 1] = a[0]
    S[2, 2] = 0.0


@njit(cache=True, nogil=True)
def _mm(A, B, transpose_a, out):
    """out = A B (or Aᵀ B) for 3×3 matrices."""
    for i in range(3):
        for m in range(3):
            s = 0.0
            for k in range(3):
                s += (A[k, i] if transpose_a else A[i, k]) * B[k, m]
            out[i, m] = s


@njit(cache=True, nogil=True)
def _add_curvature_hessian(y, s, scale, H):
    """H += scale · ∂²b/∂y² for b = x_,s · n (s = 2, 3, 4), formulas in the module docstring."""
    v, j, n = _normal(y)
    c = y[s]
    cv = _dot(c, v)
    cn = cv / j
    j3 = j ** 3
    P = np.empty((3, 3))
    Gvv = np.empty((3, 3))
    r = np.empty(3)
    for i in range(3):
        r[i] = (c[i] - cn * n[i]) / j
        for m in range(3):
            dl = 1.0 if i == m else 0.0
            P[i, m] = (dl - n[i] * n[m]) / j
            Gvv[i, m] = (-c[i] * v[m] - v[i] * c[m] - cv * dl + 3.0 * cv * n[i] * n[m]) / j3
    J1 = np.empty((3, 3))
    J2 = np.empty((3, 3))
    R = np.empty((3, 3))
    _skew(y[1], J1)
    for i in range(3):
        for m in range(3):
            J1[i, m] = -J1[i, m]  # ∂v/∂x_,1 = −[x_,2]×
    _skew(y[0], J2)  # ∂v/∂x_,2 = [x_,1]×
    _skew(r, R)
    T = np.empty((3, 3))
    Bc1 = np.empty((3, 3))
    Bc2 = np.empty((3, 3))
    B11 = np.empty((3, 3))
    B22 = np.empty((3, 3))
    B12 = np.empty((3, 3))
    _mm(P, J1, False, Bc1)  # ∂²b/∂x_,s∂x_,1 = (I − nn)/j · ∂v/∂x_,1
    _mm(P, J2, False, Bc2)
    _mm(Gvv, J1, False, T)
    _mm(J1, T, True, B11)
    _mm(Gvv, J2, False, T)
    _mm(J2, T, True, B22)
    _mm(J1, T, True, B12)
    o = 3 * s
    for i in range(3):
        for m in range(3):
            b12 = B12[i, m] - R[i, m]
            H[i, m] += scale * B11[i, m]
            H[3 + i, 3 + m] += scale * B22[i, m]
            H[i, 3 + m] += scale * b12
            H[3 + m, i] += scale * b12
            H[o + i, m] += scale * Bc1[i, m]
            H[m, o + i] += scale * Bc1[i, m]
            H[o + i, 3 + m] += scale * Bc2[i, m]
            H[3 + m, o + i] += scale * Bc2[i, m]


@njit(cache=True, nogil=True)
def gradient_hessian_point(y, Y, D, h, g, H, want_hessian):
    """g = ∂w/∂y (15,) and, if want_hessian, H = ∂²w/∂y² (15, 15); returns (w_m, w_b).

    ∂w/∂y = h Jeᵀ D e + h³/12 Jkᵀ D k,
    ∂²w/∂y² = h JeᵀDJe + h³/12 JkᵀDJk + Σ_c σ_c ∂²e_c + Σ_c μ_c ∂²k_c,  σ = hDe, μ = h³/12 Dk.
    """
    e = np.empty(3)
    k = np.empty(3)
    strains_point(y, Y, e, k)
    Je = np.empty((3, 15))
    Jk = np.empty((3, 15))
    strain_jacobians_point(y, Je, Jk)
    hb = h ** 3 / 12.0
    sig = np.zeros(3)
    mu = np.zeros(3)
    for I in range(3):
        for J in range(3):
            sig[I] += h * D[I, J] * e[J]
            mu[I] += hb * D[I, J] * k[J]
    for col in range(15):
        s = 0.0
        for I in range(3):
            s += Je[I, col] * sig[I] + Jk[I, col] * mu[I]
        g[col] = s
    if want_hessian:
        DJe = np.zeros((3, 15))
        DJk = np.zeros((3, 15))
        for I in range(3):
            for J in range(3):
                for col in range(15):
                    DJe[I, col] += h * D[I, J] * Je[J, col]
                    DJk[I, col] += hb * D[I, J] * Jk[J, col]
        for r in range(15):
            for col in range(15):
                s = 0.0
                for I in range(3):
                    s += Je[I, r] * DJe[I, col] + Jk[I, r] * DJk[I, col]
                H[r, col] = s
        for i in range(3):
            H[i, i] += sig[0]
            H[3 + i, 3 + i] += sig[1]
            H[i, 3 + i] += sig[2]
            H[3 + i, i] += sig[2]
        for c in range(3):
            _add_curvature_hessian(y, CURV_SLOT[c], -VOIGT_FACTOR[c] * mu[c], H)
    wm = 0.0
    wb = 0.0
    for I in range(3):
        wm += 0.5 * e[I] * sig[I]
        wb += 0.5 * k[I] * mu[I]
    return wm, wb


@njit(cache=True, nogil=True)
def kinematics_point(q, indptr, indices, basis, reference, U, y):
    """y (5, 3) = Y + Σ_a (p_a,1, p_a,2, p_a,11, p_a,12, p_a,22) U_a at point q."""
    for kk in range(5):
        for i in range(3):
            y[kk, i] = reference[q, kk, i]
    for t in range(indptr[q], indptr[q + 1]):
        a = indices[t]
        for kk in range(5):
            p = basis[t, kk + 1]
            for i in range(3):
                y[kk, i] += p * U[a, i]
