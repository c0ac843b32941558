"""Compressible neo-Hookean strain energy on linear triangles in plane strain (numba kernels).

Material (Millán 2012 §5.2; Millán & Arroyo 2013), per unit reference volume::

    W(F) = μ/2 (I₁ − 2 − 2 ln J) + λ/2 (ln J)²,   I₁ = tr FᵀF,  J = det F,

with F the 2 × 2 in-plane deformation gradient. This is the three-dimensional
W₃ = μ/2 (tr F₃ᵀF₃ − 3 − 2 ln J) + λ/2 (ln J)² at F₃ = diag(F, 1) (plane strain:
tr F₃ᵀF₃ = I₁ + 1). Its first Piola–Kirchhoff stress and tangent moduli are::

    P = ∂W/∂F = μ F + (λ ln J − μ) F⁻ᵀ
    ∂P_iJ/∂F_kL = μ δ_ik δ_JL + λ F⁻¹_Ji F⁻¹_Lk − (λ ln J − μ) F⁻¹_Jk F⁻¹_Li,

so that at F = I + H, P = μ (H + Hᵀ) + λ tr H I + O(|H|²): Hooke's law in plane strain with
the Lamé constants λ, μ (units of stress, force / length²). W = +∞ for J ≤ 0.

On a linear triangle with reference corners X₀, X₁, X₂ and current ones x₀, x₁, x₂,
F = D_s D_m⁻¹ with D_s = [x₁ − x₀, x₂ − x₀], D_m = [X₁ − X₀, X₂ − X₀] (columns), and the
reference gradients of the hat functions are ∇N₁ = row 0 of G = D_m⁻¹, ∇N₂ = row 1,
∇N₀ = −∇N₁ − ∇N₂. The elastic energy (per unit thickness, energy / length) and internal
forces (force / length) are::

    V(x) = Σ_e A_e W(F_e),    f_a = ∂V/∂x_a = Σ_{e ∋ a} A_e P(F_e) ∇N_a.

Positions x are (n, 2) arrays; forces are (n, 2); the tangent K = ∂²V/∂x² is a sparse
(2n × 2n) matrix with DOF 2a + i for component i of node a.
"""
from __future__ import annotations

import numpy as np
from numba import njit


def reference_gradients(nodes: np.ndarray, triangles: np.ndarray):
    """(G, A): G = D_m⁻¹ (m, 2, 2), 1 / length, and the reference areas A (m,), length²."""
    p = nodes[triangles]
    Dm = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]], axis=2)   # columns X₁−X₀, X₂−X₀
    area = 0.5 * (Dm[:, 0, 0] * Dm[:, 1, 1] - Dm[:, 0, 1] * Dm[:, 1, 0])
    return np.ascontiguousarray(np.linalg.inv(Dm)), area


@njit(cache=True, inline="always")
def _deformation_gradient(x, triangles, G, e):
    """(F₀₀, F₀₁, F₁₀, F₁₁) of triangle e: F = D_s G_e."""
    i0, i1, i2 = triangles[e, 0], triangles[e, 1], triangles[e, 2]
    d00, d01 = x[i1, 0] - x[i0, 0], x[i2, 0] - x[i0, 0]
    d10, d11 = x[i1, 1] - x[i0, 1], x[i2, 1] - x[i0, 1]
    return (d00 * G[e, 0, 0] + d01 * G[e, 1, 0], d00 * G[e, 0, 1] + d01 * G[e, 1, 1],
            d10 * G[e, 0, 0] + d11 * G[e, 1, 0], d10 * G[e, 0, 1] + d11 * G[e, 1, 1])


@njit(cache=True)
def elastic_energy(x, triangles, G, area, lam, mu):
    """V(x) = Σ_e A_e W(F_e) (energy per unit thickness); +∞ if a triangle has J ≤ 0."""
    total = 0.0
    for e in range(triangles.shape[0]):
        F00, F01, F10, F11 = _deformation_gradient(x, triangles, G, e)
        J = F00 * F11 - F01 * F10
        if J <= 0.0:
            return np.inf
        lnJ = np.log(J)
        I1 = F00 * F00 + F01 * F01 + F10 * F10 + F11 * F11
        total += area[e] * (0.5 * mu * (I1 - 2.0 - 2.0 * lnJ) + 0.5 * lam * lnJ * lnJ)
    return total


@njit(cache=True)
def internal_forces(x, triangles, G, area, lam, mu, out):
    """f = ∂V/∂x written into ``out`` (n, 2); returns the smallest J. When it is ≤ 0 a
    triangle is inverted and ``out`` is not meaningful."""
    out[:] = 0.0
    jmin = np.inf
    for e in range(triangles.shape[0]):
        i0, i1, i2 = triangles[e, 0], triangles[e, 1], triangles[e, 2]
        F00, F01, F10, F11 = _deformation_gradient(x, triangles, G, e)
        J = F00 * F11 - F01 * F10
        if J < jmin:
            jmin = J
        if J <= 0.0:
            return jmin
        c = (lam * np.log(J) - mu) / J            # P = μ F + c J F⁻ᵀ, J F⁻ᵀ = cof F
        P00, P01 = mu * F00 + c * F11, mu * F01 - c * F10
        P10, P11 = mu * F10 - c * F01, mu * F11 + c * F00
        a = area[e]
        g00, g01, g10, g11 = G[e, 0, 0], G[e, 0, 1], G[e, 1, 0], G[e, 1, 1]
        f1x = a * (P00 * g00 + P01 * g01)
        f1y = a * (P10 * g00 + P11 * g01)
        f2x = a * (P00 * g10 + P01 * g11)
        f2y = a * (P10 * g10 + P11 * g11)
        out[i1, 0] += f1x
        out[i1, 1] += f1y
        out[i2, 0] += f2x
        out[i2, 1] += f2y
        out[i0, 0] -= f1x + f2x
        out[i0, 1] -= f1y + f2y
    return jmin


@njit(cache=True)
def element_stiffness(x, triangles, G, area, lam, mu):
    """K_e (m, 6, 6) = A_e ∇N_a,J (∂P_iJ/∂F_kL) ∇N_b,L, local DOF 2a + i (a the corner);
    NaN for a triangle with J ≤ 0."""
    m = triangles.shape[0]
    K = np.empty((m, 6, 6))
    grad = np.empty((3, 2))
    Fi = np.empty((2, 2))
    for e in range(m):
        g = G[e]
        F00, F01, F10, F11 = _deformation_gradient(x, triangles, G, e)
        J = F00 * F11 - F01 * F10
        if J <= 0.0:
            K[e] = np.nan
            continue
        Fi[0, 0], Fi[0, 1], Fi[1, 0], Fi[1, 1] = F11 / J, -F01 / J, -F10 / J, F00 / J
        b = lam * np.log(J) - mu
        for J_ in range(2):
            grad[1, J_] = g[0, J_]
            grad[2, J_] = g[1, J_]
            grad[0, J_] = -g[0, J_] - g[1, J_]
        for p in range(3):
            for i in range(2):
                for q in range(3):
                    for k in range(2):
                        s = 0.0
                        for J_ in range(2):
                            for L in range(2):
                                C = lam * Fi[J_, i] * Fi[L, k] - b * Fi[J_, k] * Fi[L, i]
                                if i == k and J_ == L:
                                    C += mu
                                s += grad[p, J_] * C * grad[q, L]
                        K[e, 2 * p + i, 2 * q + k] = area[e] * s
    return K


def element_dofs(triangles: np.ndarray) -> np.ndarray:
    """Global DOFs (m, 6) of each triangle: 2a + i for corner a, component i."""
    return (2 * triangles[:, :, None] + np.arange(2)).reshape(len(triangles), 6)


def tangent_stiffness(x, triangles, G, area, lam, mu):
    """K = ∂²V/∂x² as a scipy CSR matrix (2n × 2n), force / length per length."""
    from scipy.sparse import coo_matrix

    Ke = element_stiffness(x, triangles, G, area, lam, mu)
    dofs = element_dofs(triangles)
    rows = np.repeat(dofs, 6, axis=1).ravel()
    cols = np.tile(dofs, (1, 6)).ravel()
    n = 2 * len(x)
    return coo_matrix((Ke.ravel(), (rows, cols)), shape=(n, n)).tocsr()
