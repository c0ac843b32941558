"""Optimal superposition (Kabsch) of one configuration on a reference, and the chain rule of a
function of the aligned coordinates back to the raw ones, rotation derivative included.

Training frames are superposed with mdtraj (:func:`pointatlas_molecular.ensemble.aligned`);
this module exists because a collective variable ξ(x) = ξ̂(z(x)) of the *aligned*
coordinates z needs ∂ξ/∂x at every MD step, and no library gives the derivative of the
optimal rotation.

Notation (lengths in nm): atoms i with weights w_i (Σ w_i = 1), raw positions x_i, centroid
c = Σ w_i x_i, y_i = x_i − c, reference r_i (centred: Σ w_i r_i = 0). B = Σ w_i y_i r_iᵀ; the
rotation R ∈ SO(3) maximising tr(R B) (minimising Σ w_i |R y_i − r_i|²) is
R = V diag(1, 1, det(V Uᵀ)) Uᵀ for B = U Σ Vᵀ (Kabsch, Acta Cryst. A32 (1976) 922), and
z_i = R y_i.

Derivative. Optimality means S = R B is symmetric. With dR = Ŵ R (ω the axial vector of the
skew Ŵ), the symmetric part of d(RB) = Ŵ S + R dB gives, by Ŵ S + S Ŵ = (((tr S) I − S) ω)^,

    A ω = −Σ_j w_j r_j × (R dy_j),   A = (tr S) I − S,

and dz_i = R dy_i + ω × z_i. For a scalar ξ with ∂ξ/∂z_i = g_i, τ = Σ_i z_i × g_i and
s = A⁻¹ τ:

    ∂ξ/∂y_j = Rᵀ (g_j − w_j s × r_j),   ∂ξ/∂x_j = ∂ξ/∂y_j − w_j Σ_l ∂ξ/∂y_l.

A is singular only for a collinear reference (rotation about that line undefined).
"""
from __future__ import annotations

import numba as nb
import numpy as np


@nb.njit(cache=True)
def superpose(x, ref, w, z, R):
    """Aligned coordinates z (n, 3) and rotation R (3, 3) of x (n, 3) on the centred ``ref``
    with weights ``w`` (summing to 1). Returns the smallest eigenvalue of A = tr(S) I − S
    (near 0: the superposition is degenerate and its derivative undefined)."""
    n = x.shape[0]
    c = np.zeros(3)
    for i in range(n):
        for k in range(3):
            c[k] += w[i] * x[i, k]
    B = np.zeros((3, 3))
    for i in range(n):
        for a in range(3):
            ya = x[i, a] - c[a]
            for b in range(3):
                B[a, b] += w[i] * ya * ref[i, b]
    U, sig, Vt = np.linalg.svd(B)
    V = Vt.T
    Ut = U.T
    det = np.linalg.det(V @ Ut)
    D = np.eye(3)
    D[2, 2] = 1.0 if det >= 0 else -1.0
    R[:, :] = V @ D @ Ut
    for i in range(n):
        for a in range(3):
            s = 0.0
            for b in range(3):
                s += R[a, b] * (x[i, b] - c[b])
            z[i, a] = s
    # eigenvalues of A = tr(S) I − S are σ_i + σ_j (σ_3 signed by det)
    s3 = sig[2] * D[2, 2]
    return min(sig[0] + sig[1], sig[0] + s3, sig[1] + s3)


@nb.njit(cache=True)
def pull_back(g, z, R, ref, w, out):
    """∂ξ/∂x (n, 3) into ``out`` from g = ∂ξ/∂z (n, 3) (module docstring)."""
    n = z.shape[0]
    S = np.zeros((3, 3))          # S = R B = Σ w_i z_i r_iᵀ
    tau = np.zeros(3)
    for i in range(n):
        for a in range(3):
            for b in range(3):
                S[a, b] += w[i] * z[i, a] * ref[i, b]
        tau[0] += z[i, 1] * g[i, 2] - z[i, 2] * g[i, 1]
        tau[1] += z[i, 2] * g[i, 0] - z[i, 0] * g[i, 2]
        tau[2] += z[i, 0] * g[i, 1] - z[i, 1] * g[i, 0]
    tr = S[0, 0] + S[1, 1] + S[2, 2]
    A = -0.5 * (S + S.T)
    for a in range(3):
        A[a, a] += tr
    s = np.linalg.solve(A, tau)
    total = np.zeros(3)
    for j in range(n):
        v0 = g[j, 0] - w[j] * (s[1] * ref[j, 2] - s[2] * ref[j, 1])
        v1 = g[j, 1] - w[j] * (s[2] * ref[j, 0] - s[0] * ref[j, 2])
        v2 = g[j, 2] - w[j] * (s[0] * ref[j, 1] - s[1] * ref[j, 0])
        for a in range(3):
            out[j, a] = R[0, a] * v0 + R[1, a] * v1 + R[2, a] * v2
            total[a] += out[j, a]
    for j in range(n):
        for a in range(3):
            out[j, a] -= w[j] * total[a]


def align(x, ref, w=None):
    """(z, R) of x (n, 3) superposed on ``ref`` (centred here), uniform weights by default."""
    x = np.ascontiguousarray(x, dtype=np.float64)
    w = np.full(len(x), 1.0 / len(x)) if w is None else np.asarray(w, np.float64) / np.sum(w)
    ref = np.ascontiguousarray(ref - w @ ref, dtype=np.float64)
    z, R = np.empty_like(x), np.empty((3, 3))
    superpose(x, ref, w, z, R)
    return z, R
