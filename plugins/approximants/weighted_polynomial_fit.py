"""Consistent derivatives on irregular nodes: the LME-weighted polynomial fit.

LME basis functions reproduce linear functions only, so their exact Hessians ∂²p_a are not
consistent on irregular nodes: on uniformly random nodes in the plane, Σ_a ∂²p_a f_a for
f = |x|² (Laplacian 4) scatters with a standard deviation of about 3. This module uses
instead, at each evaluation point x, the weighted least-squares polynomial fit of degree k,

    c(x) = argmin_c Σ_a p_a(x) (q(x_a - x)·c - f_a)²,   q(y) = monomials of y of degree ≤ k,

i.e. the shape functions Ñ_a(x) = q(0)·M⁻¹ p_a q(x_a - x), M = Σ_a p_a q q^T, of moving
least squares with the LME values as weights, and their "diffuse derivatives" ∂_y, ∂²_y
[q(y)·M⁻¹ p_a q(x_a - x)] at y = 0 (Nayroles, Touzot & Villon, Comput. Mech. 10:307, 1992).
They reproduce every polynomial of degree ≤ k exactly, on any node set with a
non-degenerate moment matrix. For smooth f the Hessian error is O(σ^{k-1}) (σ ~ h/√γ the
width of the weights): the degree-(k+1) terms give an O(σ^{k-1}) scatter and, for even
k + 2, the degree-(k+2) terms an O(σ^k) bias that does not average out. Measured on 2 800
random nodes of a spherical cap (h = 0.026, γ = 0.8), mean curvature error mean/std with
the weights p_a: quadratic 3.0e-3/1.1e-2, cubic 2.8e-3/1.0e-3, quartic −1.1e-5/8.5e-5
(with LME's prior as weights, see below: 3.6e-3/8.5e-3, 2.8e-3/9.6e-4, −1.7e-5/7.6e-5).

The LME basis uses the fit as a whole basis (``reproduction``) with the Gaussian prior of
LME, exp(-β_a|x - x_a|²), as weights rather than p_a: p_a is tilted by its Lagrange
multiplier towards a few nodes at the rim of a gap in the samples, where the fit then is
ill-posed (20 000 random points on a sphere: Willmore energy 6.3e-3 off with p_a, 3.3e-4
with the prior, measured).

The diffuse derivatives are not the derivatives of Ñ_a, and Ñ_a may be negative: use them
for geometry (positions, tangents, curvatures of a chart through samples), not as the
shape functions of a Galerkin method (as the bending operator of a Kirchhoff–Love shell,
the consistent Hessians made a clamped plate 57 % too soft, measured).
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True)
def n_monomials(d: int, degree: int) -> int:
    """Number of monomials of degree ≤ ``degree`` (2 to 4) in d variables."""
    m = 1 + d + d * (d + 1) // 2
    if degree >= 3:
        m += d * (d + 1) * (d + 2) // 6
    if degree >= 4:
        m += d * (d + 1) * (d + 2) * (d + 3) // 24
    return m


@njit(cache=True)
def _monomials(y: np.ndarray, q: np.ndarray, degree: int) -> None:
    """q = (1, y_i, y_i y_j (i ≤ j), y_i y_j y_k (i ≤ j ≤ k), ...) up to ``degree``."""
    d = y.shape[0]
    q[0] = 1.0
    for i in range(d):
        q[1 + i] = y[i]
    c = 1 + d
    for i in range(d):
        for j in range(i, d):
            q[c] = y[i] * y[j]
            c += 1
    if degree >= 3:
        for i in range(d):
            for j in range(i, d):
                for k in range(j, d):
                    q[c] = y[i] * y[j] * y[k]
                    c += 1
    if degree >= 4:
        for i in range(d):
            for j in range(i, d):
                for k in range(j, d):
                    for l in range(k, d):
                        q[c] = y[i] * y[j] * y[k] * y[l]
                        c += 1


#: relative weight below which a node takes no part in a row's fit
WEIGHT_CUTOFF = 1e-8


#: the largest Lebesgue constant Λ(x) = Σ_a |Ñ_a(x)| accepted for a row of the fit before its
#: weights are widened. Λ bounds the fit's error by (1 + Λ) × the best local polynomial
#: approximation (Wendland, *Scattered Data Approximation*, 2005, Thm 4.7 and §4.2), and
#: amplifies the noise of the samples (an embedding ξ of points is exact only to its stress)
#: by Λ in values and more in derivatives. Measured on quartic charts: median 1.4, 99th
#: percentile 4.0 on 5 000 random sphere points; on a pyvista ParametricEllipsoid grid, whose
#: meridians lie 3 spacings apart, 99th percentile 717 where the weights sit on one meridian,
#: with tangent planes collapsed (J → 0) and ∫K dA = 0.05·4π.
MAX_LEBESGUE = 5.0
#: the gradients' Lebesgue constant h Σ_a |∇Ñ_a(x)| counts with this factor against the same
#: bound: it is about twice the values' where the fit is sound (median 2.8 against 1.4 on the
#: random sphere), and it is the one that grows where a chart's tangent plane collapses (a
#: ParametricEllipsoid row with Λ = 3.9 had h Σ|∇Ñ_a| = 186 and J ≈ 0 there)
GRADIENT_LEBESGUE_SCALE = 0.5
#: the weights of a row whose Λ exceeds MAX_LEBESGUE are widened, w → w^s (a Gaussian prior
#: exp(−β r²) becomes exp(−sβ r²)), for these s in turn, then its degree lowered (to 2); the
#: row keeps the first fit within the bound, else the one of least Λ
WIDENINGS = (1.0, 0.5, 0.25, 0.125)


@njit(cache=True)
def _row_fit(a0, a1, weights, s, indices, nodes, x, h, degree, max_condition, coef):
    """The fit of degree ``degree`` of one row with weights w_a^s: writes the coefficients
    per unit f_a, coef[e, c] = (A⁺)_{c e} √w_e (c < the degree's monomials), and returns its Lebesgue constant Σ_e |coef[e, 0]|
    (−1 if the row has fewer used entries than monomials or cond(A) > max_condition)."""
    d = nodes.shape[1]
    m = n_monomials(d, degree)
    wmax = 0.0
    for e in range(a0, a1):
        wmax = max(wmax, weights[e] ** s)
    # entries below WEIGHT_CUTOFF·max take no part (zero coefficients): they change the
    # fit by ~1e-8 and would add half to its cost in d = 3
    used = np.empty(a1 - a0, dtype=np.int64)
    n = 0
    for e in range(a1 - a0):
        if weights[a0 + e] ** s > WEIGHT_CUTOFF * wmax:
            used[n] = e
            n += 1
    if n < m:
        return -1.0
    q = np.empty(m)
    y = np.empty(d)
    A = np.empty((n, m))
    for u in range(n):
        e = used[u]
        for i in range(d):
            y[i] = (nodes[indices[a0 + e], i] - x[i]) / h
        _monomials(y, q, degree)
        r = np.sqrt(weights[a0 + e] ** s)
        for c in range(m):
            A[u, c] = r * q[c]
    U, sv, Vt = np.linalg.svd(A, full_matrices=False)
    if sv[m - 1] <= 0.0 or sv[0] > max_condition * sv[m - 1]:
        return -1.0
    coef[:, :m] = 0.0
    lebesgue = 0.0
    lebesgue_gradient = 0.0
    for u in range(n):
        e = used[u]
        r = np.sqrt(weights[a0 + e] ** s)
        for c in range(m):
            acc = 0.0
            for t in range(m):
                acc += Vt[t, c] * U[u, t] / sv[t]
            coef[e, c] = acc * r
        lebesgue += abs(coef[e, 0])
        g2 = 0.0
        for i in range(d):
            g2 += coef[e, 1 + i] ** 2
        lebesgue_gradient += np.sqrt(g2)
    return max(lebesgue, GRADIENT_LEBESGUE_SCALE * lebesgue_gradient)


@njit(cache=True, parallel=True)
def _fit_rows(indptr, indices, weights, nodes, points, h, max_condition, degree,
              values, gradients, hessians, all_orders, max_lebesgue, widenings):
    """Per row k (an evaluation point), the pseudo-inverse of the weighted design matrix
    A = diag(√w_a) Q (n × m) by SVD, with offsets scaled by the length ``h``, so the error
    grows with cond(A), not cond(A)² as with the moment matrix; then the fit coefficients
    per unit f_a, (A⁺)_{c e} √w_a.

    A row whose Lebesgue constant exceeds ``max_lebesgue`` is fitted again with the weights
    widened, w^s for s in ``widenings`` (after the first), then with the degree lowered
    (down to 2) and the same widths: it keeps the first fit within the bound, else the one
    of least Λ (points sampled along lines a few spacings apart carry a quadratic across
    them but not a quartic). Writes the Hessians and, with ``all_orders``, the values and
    gradients. The ``weights`` w_a (≥ 0) are read before ``values`` is written, so the two
    may be one array. Rows where no width and degree give as many used entries as
    monomials and cond(A) ≤ ``max_condition`` (the weight sits on a few nodes, as at the
    hull of the nodes) are left as they are.

    Returns the number of such rows and, per row, the degree used (0: left as is).
    """
    d = nodes.shape[1]
    m = n_monomials(d, degree)
    skipped = np.zeros(points.shape[0], dtype=np.int64)
    used_degree = np.zeros(points.shape[0], dtype=np.int64)
    for k in prange(points.shape[0]):
        a0, a1 = indptr[k], indptr[k + 1]
        coef = np.empty((a1 - a0, m))
        best = np.zeros((a1 - a0, m))
        best_lebesgue = np.inf
        best_degree = 0
        for p in range(degree, 1, -1):
            for s in widenings:
                lebesgue = _row_fit(a0, a1, weights, s, indices, nodes, points[k], h, p,
                                    max_condition, coef)
                if lebesgue >= 0.0 and lebesgue < best_lebesgue:
                    best_lebesgue = lebesgue
                    best_degree = p
                    best[:, :] = 0.0
                    best[:, :n_monomials(d, p)] = coef[:, :n_monomials(d, p)]
                if best_lebesgue <= max_lebesgue:
                    break
            if best_lebesgue <= max_lebesgue or max_lebesgue == np.inf:
                break
        if best_degree == 0:
            skipped[k] = 1
            continue
        used_degree[k] = best_degree
        for e in range(a1 - a0):
            c = 1 + d
            for i in range(d):
                for j in range(i, d):
                    s2 = (2.0 if i == j else 1.0) * best[e, c] / (h * h)
                    hessians[a0 + e, i, j] = s2
                    hessians[a0 + e, j, i] = s2
                    c += 1
            if all_orders:
                for i in range(d):
                    gradients[a0 + e, i] = best[e, 1 + i] / h
                values[a0 + e] = best[e, 0]
    return int(skipped.sum()), used_degree


@njit(cache=True)
def consistent_hessians(indptr: np.ndarray, indices: np.ndarray, values: np.ndarray,
                        nodes: np.ndarray, points: np.ndarray, h: float,
                        max_condition: float, hessians: np.ndarray) -> int:
    """Overwrite ``hessians`` (nnz, d, d) with the diffuse Hessians of the LME-weighted
    quadratic fit (module docstring, k = 2): Σ_a H̃_a f_a = ∂²f for every quadratic f, so
    Σ H̃_a = 0 and Σ H̃_a ⊗ x_a = 0. ``h`` is the length that scales the offsets (the median
    node spacing). Skipped rows (see :func:`_fit_rows`) keep their exact Hessians; returns
    their number."""
    return _fit_rows(indptr, indices, values, nodes, points, h, max_condition, 2,
                     values, np.zeros((0, nodes.shape[1])), hessians, False, np.inf,
                     (1.0,))[0]


@njit(cache=True)
def polynomial_fit_basis(indptr: np.ndarray, indices: np.ndarray, values: np.ndarray,
                         gradients: np.ndarray, nodes: np.ndarray, points: np.ndarray,
                         h: float, max_condition: float, degree: int,
                         hessians: np.ndarray, weights: np.ndarray,
                         max_lebesgue: float = MAX_LEBESGUE) -> np.ndarray:
    """Overwrite the LME values, gradients and Hessians (CSR rows, as from
    ``LocalMaxEnt.evaluate``) with Ñ_a, ∇̃N_a, H̃_a of the polynomial fit of ``degree`` 2, 3
    or 4 with the given ``weights`` (nnz,) in place of p_a (module docstring): they reproduce
    polynomials of that degree, their gradients and Hessians, whatever the weights. A chart
    Σ Ñ_a P_a through samples P_a of a smooth manifold is then O(σ^{k+1}) off it, with
    curvatures O(σ^{k-1}). A row whose Lebesgue constant exceeds ``max_lebesgue`` (np.inf:
    never) is fitted with wider weights (:data:`WIDENINGS`), then a lower degree. Skipped
    rows keep all their LME arrays. Returns the degree each row used (0: skipped)."""
    return _fit_rows(indptr, indices, weights, nodes, points, h, max_condition, degree,
                     values, gradients, hessians, True, max_lebesgue, WIDENINGS)[1]
