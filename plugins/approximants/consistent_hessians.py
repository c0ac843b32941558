"""Second-order consistent Hessians of a positive basis: diffuse derivatives of a local fit.

LME basis functions reproduce linear functions only, so their exact Hessians ∂²p_a are not
consistent on irregular nodes: on uniformly random nodes in the plane, Σ_a ∂²p_a f_a for
f = |x|² (Laplacian 4) scatters with a standard deviation of about 3. This module replaces
them by the Hessian of the weighted least-squares quadratic fit at x,

    c(x) = argmin_c Σ_a p_a(x) (q(x_a - x)·c - f_a)²,   q(y) = (1, y_i, y_i y_j (i ≤ j)),
    H̃_a(x) = ∂²/∂y² [q(y)·M⁻¹ p_a q(x_a - x)] at y = 0,   M = Σ_a p_a q q^T,

the "diffuse derivative" of Nayroles, Touzot & Villon (Comput. Mech. 10:307, 1992) with the
LME values as weights. Σ_a H̃_a f_a = ∂²f exactly for every quadratic f on any node set
with a non-degenerate moment matrix (so Σ H̃_a = 0 and Σ H̃_a ⊗ x_a = 0), and the error for
smooth f is O(h). H̃_a is not the derivative of ∇p_a. Use it to evaluate curvatures; as
the bending operator of a Kirchhoff–Love shell it made a clamped plate 57 % too soft
(measured), so shells keep the exact Hessians.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _monomials(y: np.ndarray, q: np.ndarray) -> None:
    d = y.shape[0]
    q[0] = 1.0
    for i in range(d):
        q[1 + i] = y[i]
    c = 1 + d
    for i in range(d):
        for j in range(i, d):
            q[c] = y[i] * y[j]
            c += 1


@njit(cache=True)
def consistent_hessians(indptr: np.ndarray, indices: np.ndarray, values: np.ndarray,
                        nodes: np.ndarray, points: np.ndarray, h: float,
                        max_condition: float, hessians: np.ndarray) -> int:
    """Overwrite ``hessians`` (nnz, d, d) with the diffuse Hessians H̃_a of the module docstring.

    The fit is solved by the SVD of the weighted design matrix A = diag(√p_a) Q (n × m), with
    offsets scaled by the length ``h`` (the median node spacing), so the error grows with
    cond(A), not cond(A)² as with the moment matrix. Rows with fewer entries than monomials,
    or with cond(A) above ``max_condition`` (the weight sits on a few nodes, as at the hull
    of the nodes), keep their exact Hessians. Returns the number of such rows.
    """
    d = nodes.shape[1]
    m = 1 + d + d * (d + 1) // 2
    q = np.empty(m)
    y = np.empty(d)
    fallback = 0
    for k in range(points.shape[0]):
        a0, a1 = indptr[k], indptr[k + 1]
        n = a1 - a0
        if n < m:
            fallback += 1
            continue
        A = np.empty((n, m))
        for e in range(n):
            for i in range(d):
                y[i] = (nodes[indices[a0 + e], i] - points[k, i]) / h
            _monomials(y, q)
            r = np.sqrt(max(values[a0 + e], 0.0))
            for c in range(m):
                A[e, c] = r * q[c]
        U, sv, Vt = np.linalg.svd(A, full_matrices=False)
        if sv[m - 1] <= 0.0 or sv[0] > max_condition * sv[m - 1]:
            fallback += 1
            continue
        # coefficient c of the fit per unit f_a: (A⁺)_{c e} √p_a, A⁺ = V Σ⁻¹ U^T
        for e in range(n):
            r = np.sqrt(max(values[a0 + e], 0.0)) / (h * h)
            c = 1 + d
            for i in range(d):
                for j in range(i, d):
                    coef = 0.0
                    for t in range(m):
                        coef += Vt[t, c] * U[e, t] / sv[t]
                    coef *= r
                    if i == j:
                        hessians[a0 + e, i, i] = 2.0 * coef
                    else:
                        hessians[a0 + e, i, j] = coef
                        hessians[a0 + e, j, i] = coef
                    c += 1
    return fallback
