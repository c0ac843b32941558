"""Differential geometry of a parametrized d-surface φ: A ⊂ R^d → R^D, pointwise on arrays.

Inputs are the derivatives of the chart at m points (Paper 1 §3.1, thesis L1200):
tangents T[:, α, :] = ∂φ/∂ξ_α (m, d, D), second derivatives S[:, α, β, :] = ∂²φ/∂ξ_α∂ξ_β
(m, d, d, D). Metric a_αβ = φ_α·φ_β, area element J = sqrt(det a). For a surface in R^3
(d = 2, D = 3): unit normal n = φ_1 × φ_2 / |φ_1 × φ_2|, second fundamental form
b_αβ = φ_αβ · n, shape operator a^{-1} b, mean curvature H = tr(a^{-1} b) = κ1 + κ2 (the
thesis convention of the Willmore energy ∫H² dA = 16π on a unit sphere, L1085) and Gaussian
curvature K = det b / det a = κ1 κ2. The sign of H follows the orientation of n; H² and K
do not depend on it.
"""
from __future__ import annotations

import numpy as np


def chart_derivatives(basis, control_points: np.ndarray, order: int = 2):
    """φ, Dφ and D²φ at the evaluation points from basis functions p_a and control points P_a.

    φ(ξ) = Σ_a p_a(ξ) P_a (thesis Eq. 2). ``basis`` is a :class:`pointatlas.basis.BasisFunctions`
    with gradients (order ≥ 1) and Hessians (order 2). Returns (X (m, D), T (m, d, D) or None,
    S (m, d, d, D) or None).
    """
    from scipy.sparse import csr_matrix

    m, n = basis.n_points, control_points.shape[0]
    shape = (m, n)

    def apply(vals):
        return csr_matrix((vals, basis.indices, basis.indptr), shape=shape) @ control_points

    X = apply(basis.values)
    T = S = None
    if order >= 1:
        d = basis.gradients.shape[1]
        T = np.stack([apply(basis.gradients[:, k]) for k in range(d)], axis=1)
    if order >= 2:
        d = basis.hessians.shape[1]
        S = np.empty((m, d, d, control_points.shape[1]))
        for k in range(d):
            for j in range(k, d):
                S[:, k, j] = apply(basis.hessians[:, k, j])
                S[:, j, k] = S[:, k, j]
    return X, T, S


def metric(T: np.ndarray) -> np.ndarray:
    """First fundamental form a_αβ = φ_α · φ_β, (m, d, d)."""
    return np.einsum("mai,mbi->mab", T, T)


def area_element(T: np.ndarray) -> np.ndarray:
    """J = sqrt(det a), the d-volume element of the chart (thesis §3.4), (m,)."""
    return np.sqrt(np.clip(np.linalg.det(metric(T)), 0.0, None))


def unit_normal(T: np.ndarray) -> np.ndarray:
    """n = φ_1 × φ_2 / |φ_1 × φ_2| for a surface in R^3, (m, 3)."""
    if T.shape[1] != 2 or T.shape[2] != 3:
        raise ValueError(f"unit_normal needs a surface in R^3 (d=2, D=3); got d={T.shape[1]}, "
                         f"D={T.shape[2]}.")
    c = np.cross(T[:, 0, :], T[:, 1, :])
    return c / np.linalg.norm(c, axis=1, keepdims=True)


def second_fundamental_form(S: np.ndarray, n: np.ndarray) -> np.ndarray:
    """b_αβ = φ_αβ · n, (m, d, d)."""
    return np.einsum("mabi,mi->mab", S, n)


def shape_operator(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Mixed components of the Weingarten map, a^{-1} b, (m, d, d)."""
    return np.linalg.solve(a, b)


def mean_curvature(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """H = tr(a^{-1} b) = κ1 + κ2 (not halved), (m,)."""
    return np.trace(shape_operator(a, b), axis1=1, axis2=2)


def gaussian_curvature(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """K = det b / det a = κ1 κ2, (m,)."""
    return np.linalg.det(b) / np.linalg.det(a)


def principal_curvatures(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """κ1 ≥ κ2 (m, 2), roots of κ² − H κ + K = 0."""
    H = mean_curvature(a, b)
    K = gaussian_curvature(a, b)
    disc = np.sqrt(np.clip(H**2 / 4.0 - K, 0.0, None))
    return np.column_stack([H / 2.0 + disc, H / 2.0 - disc])


def surface_geometry(T: np.ndarray, S: np.ndarray | None) -> dict[str, np.ndarray]:
    """All pointwise quantities at once: metric, J, and (D = 3, d = 2, S given) n, b, H, K."""
    a = metric(T)
    out = {"metric": a, "area_element": np.sqrt(np.clip(np.linalg.det(a), 0.0, None))}
    if S is not None and T.shape[1] == 2 and T.shape[2] == 3:
        n = unit_normal(T)
        b = second_fundamental_form(S, n)
        out.update(normal=n, second_fundamental_form=b,
                   mean_curvature=mean_curvature(a, b), gaussian_curvature=gaussian_curvature(a, b))
    return out
