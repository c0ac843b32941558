"""Closest-point projection on an LME-parametrised manifold X(ξ) = Σ_a p_a(ξ) P_a, for one
configuration at a time, with the Jacobian ∂ξ/∂z by the implicit function theorem (numba).

Hashemian, Millán & Arroyo, J. Chem. Phys. 139 (2013) 214101, §II.C: the collective variable
of an (aligned) configuration z ∈ R^D is the preimage ξ(z) of its closest point on the
manifold,

    ξ(z) = argmin_ξ φ(ξ),   φ = ½ |X(ξ) − z|²,   F(ξ, z) = DXᵀ (X(ξ) − z) = 0,

solved by Newton on F with the exact Hessian H = DXᵀ DX + Σ_D (X − z)_D D²X_D (Gauss–Newton's
DXᵀ DX where H is not positive definite), halving a step until φ decreases and ξ stays where
the LME basis exists. Differentiating F = 0: H dξ − DXᵀ dz = 0, so

    ∂ξ/∂z = H⁻¹ DXᵀ   (d × D),

which needs the second derivatives D²X = Σ ∇∇p_a ⊗ P_a of the LME basis. At a converged ξ
where H is not positive definite the point is not a local minimum of the distance: flagged.

Status codes: OK; OUTSIDE (ξ where no basis exists: the start point, or no step stays in the
parametrised region); NOT_CONVERGED (``max_iter`` Newton steps); NOT_A_MINIMUM (H not
positive definite at the solution); NEAR_FOCAL (the conditioning c outside
[min_conditioning, 1/min_conditioning]: near the focal set, or a fit that curves sharply away within the distance);
FOLDED (σ_min/σ_max of DX below ``FOLD_RATIO``: the fitted X(ξ) nearly folds there, so ξ
is not a coordinate of the manifold).

Conditioning: c = λ_min(G^{-1/2} H G^{-1/2}), G = DXᵀ DX, is 1 on the manifold and
1 − distance × (normal curvature) off it; c → 0 at the focal set (the centres of curvature),
where the closest point jumps between branches and ∂ξ/∂z ~ 1/c blows up. A configuration
that close to the focal set has no trustworthy CV.
"""
from __future__ import annotations

import numba as nb
import numpy as np

from pointatlas_approximants.lme_kernels import OK as LME_OK
from pointatlas_approximants.lme_kernels import derivatives, solve_dual

OK, OUTSIDE, NOT_CONVERGED, NOT_A_MINIMUM, NEAR_FOCAL, FOLDED = 0, 1, 2, 3, 4, 5
STATUS_NAMES = ("ok", "outside the parametrised region", "not converged",
                "not a minimum of the distance",
                "ill-conditioned (near the focal set, or the fit curves sharply there)",
                "where the parametrisation folds")
#: step halvings before a projection that keeps leaving the parametrised region gives up
#: (a refused configuration must stay cheap: each halving is a basis evaluation)
MAX_HALVINGS = 10
#: σ_min/σ_max of DX below this: X(ξ) is (nearly) rank-deficient, the chart folds
FOLD_RATIO = 1e-2


@nb.njit(cache=True)
def _basis(q, nodes, beta, r2, lme_tol, lme_max_iter, order, w):
    """LME p_a(q) (and derivatives up to ``order``) on the support of q; returns (k, ok).
    Support nodes in w.ent[:k], values in w.p, gradients in w.grads, Hessians in w.hess."""
    yT, d2, bl, ent, lam, p, ib, mats, vecs, S, gT, jT, hT, grads, hess = w
    n, d = nodes.shape
    k = 0
    for a in range(n):
        s = 0.0
        for j in range(d):
            t = q[j] - nodes[a, j]
            yT[j, k] = t
            s += t * t
        if s < r2[a]:
            d2[k] = s
            bl[k] = beta[a]
            ent[k] = a
            k += 1
    lam[:] = 0.0
    if solve_dual(yT, bl, d2, k, lme_tol, lme_max_iter, lam, p, mats, vecs, ib) != LME_OK:
        return k, False
    if order >= 1:
        if not derivatives(yT, bl, p, k, order, 0, grads, hess, gT, jT, hT, mats, vecs, S):
            return k, False
    return k, True


@nb.njit(cache=True)
def _manifold(k, w, P, order, X, DX, D2X):
    """X(q) (D,), DX (D, d), D²X (D, d, d) from the basis in the scratch ``w``."""
    ent, p, grads, hess = w[3], w[5], w[13], w[14]
    D = P.shape[1]
    d = DX.shape[1]
    X[:] = 0.0
    if order >= 1:
        DX[:, :] = 0.0
    if order >= 2:
        D2X[:, :, :] = 0.0
    for q in range(k):
        Pa = P[ent[q]]
        for m in range(D):
            X[m] += p[q] * Pa[m]
        if order >= 1:
            for i in range(d):
                g = grads[q, i]
                for m in range(D):
                    DX[m, i] += g * Pa[m]
        if order >= 2:
            for i in range(d):
                for j in range(i + 1):
                    h = hess[q, i, j]
                    for m in range(D):
                        D2X[m, i, j] += h * Pa[m]
    if order >= 2:
        for i in range(d):
            for j in range(i):
                for m in range(D):
                    D2X[m, j, i] = D2X[m, i, j]


@nb.njit(cache=True)
def scratch(n_nodes, d):
    """Work arrays for :func:`_basis` (one tuple, reused across calls)."""
    return (np.empty((d, n_nodes)), np.empty(n_nodes), np.empty(n_nodes),
            np.empty(n_nodes, dtype=np.int64), np.empty(d), np.empty(n_nodes),
            np.empty(n_nodes, dtype=np.int64), np.empty((5, d, d)), np.empty((4, d)),
            np.empty((d, d, d)), np.empty((d, n_nodes)), np.empty((d, n_nodes)),
            np.empty((d, d, n_nodes)), np.empty((n_nodes, d)), np.empty((n_nodes, d, d)))


@nb.njit(cache=True)
def inside_hull(q, hull):
    """Whether q satisfies every facet inequality n·q + c ≤ 0 of the nodes' convex hull
    (rows [n, c]; a tiny slack for round-off)."""
    d = q.shape[0]
    for f in range(hull.shape[0]):
        s = hull[f, d]
        for j in range(d):
            s += hull[f, j] * q[j]
        if s > 1e-12:
            return False
    return True


def hull_equations(nodes) -> np.ndarray:
    """Facet inequalities [n, c] (n·q + c ≤ 0 inside) of the convex hull of the nodes."""
    nodes = np.asarray(nodes, dtype=np.float64)
    if nodes.shape[1] == 1:
        return np.array([[1.0, -nodes.max()], [-1.0, nodes.min()]])
    from scipy.spatial import ConvexHull

    return np.ascontiguousarray(ConvexHull(nodes).equations)


@nb.njit(cache=True)
def _state(z, xi, nodes, beta, r2, P, hull, lme_tol, lme_max_iter, w, X, DX, D2X, F, H):
    """X, DX, D²X at ξ, F = DXᵀ(X − z), H = DXᵀDX + Σ (X − z) D²X; returns φ (inf outside:
    outside the nodes' hull is decided by its facets, before any costly dual solve)."""
    if not inside_hull(xi, hull):
        return np.inf
    k, ok = _basis(xi, nodes, beta, r2, lme_tol, lme_max_iter, 2, w)
    if not ok:
        return np.inf
    _manifold(k, w, P, 2, X, DX, D2X)
    D, d = DX.shape
    phi = 0.0
    for m in range(D):
        phi += 0.5 * (X[m] - z[m]) ** 2
    for i in range(d):
        s = 0.0
        for m in range(D):
            s += DX[m, i] * (X[m] - z[m])
        F[i] = s
        for j in range(i + 1):
            h = 0.0
            for m in range(D):
                h += DX[m, i] * DX[m, j] + (X[m] - z[m]) * D2X[m, i, j]
            H[i, j] = h
            H[j, i] = h
    return phi


@nb.njit(cache=True)
def project(z, xi, nodes, beta, r2, P, hull, lme_tol, lme_max_iter, tol, max_iter, min_cond,
            w, J):
    """Project z (D,) from the start ``xi`` (d,, overwritten with ξ(z)); ∂ξ/∂z into J (d, D).

    Returns (status, Newton steps taken, distance |X(ξ) − z|, conditioning c). ``tol``:
    converged when a full Newton step is shorter than ``tol`` (units of ξ); that last step is
    taken and counted. Each accepted full step costs one basis evaluation (the trial point's
    values and derivatives are the next iteration's).
    """
    D = P.shape[1]
    d = xi.shape[0]
    X, DX, D2X = np.empty(D), np.empty((D, d)), np.empty((D, d, d))
    Xt, DXt, D2Xt = np.empty(D), np.empty((D, d)), np.empty((D, d, d))
    H, Ht = np.empty((d, d)), np.empty((d, d))
    F, Ft = np.empty(d), np.empty(d)
    trial = np.empty(d)
    phi = _state(z, xi, nodes, beta, r2, P, hull, lme_tol, lme_max_iter, w, X, DX, D2X, F, H)
    if not np.isfinite(phi):
        return OUTSIDE, 0, np.inf, 0.0
    it = 0
    converged = False
    while it < max_iter:
        if np.linalg.eigvalsh(H)[0] > 0.0:
            step = -np.linalg.solve(H, F)
        else:
            step = -np.linalg.solve(DX.T @ DX, F)
        small = np.sqrt(np.sum(step * step)) < tol
        predicted = 0.0  # decrease of φ the quadratic model promises for the full step
        for i in range(d):
            predicted -= 0.5 * F[i] * step[i]
        # the round-off floor: φ (a sum of squares of differences X − z that cancel to ~1e-14
        # relative) can no longer tell a better ξ from a worse one, so no line search; the
        # full Newton step is the most accurate ξ there is (quadratic convergence), and is
        # taken unless it leaves the region. Discarding it instead left ξ 1e-10 off, and
        # finite differences of ξ 2e-5 off its gradient.
        floor = predicted <= 1e-12 * phi
        t = 1.0
        accepted = False
        for _ in range(1 if floor else MAX_HALVINGS):
            for i in range(d):
                trial[i] = xi[i] + t * step[i]
            phit = _state(z, trial, nodes, beta, r2, P, hull, lme_tol, lme_max_iter, w, Xt,
                          DXt, D2Xt, Ft, Ht)
            if (np.isfinite(phit) if floor else phit <= phi * (1.0 + 1e-14) + 1e-300):
                accepted = True
                break
            t *= 0.5
        if not accepted:
            if small or floor:  # a step φ cannot accept, below tol or its round-off: converged
                converged = True
                break
            return OUTSIDE, it, np.sqrt(2 * phi), 0.0
        X, Xt = Xt, X
        DX, DXt = DXt, DX
        D2X, D2Xt = D2Xt, D2X
        H, Ht = Ht, H
        F, Ft = Ft, F
        xi[:] = trial
        phi = phit
        it += 1
        if small or floor:
            converged = True
            break
    dist = np.sqrt(2.0 * phi)
    if np.linalg.eigvalsh(H)[0] <= 0.0:
        return NOT_A_MINIMUM, it, dist, 0.0
    G = DX.T @ DX
    g = np.linalg.eigvalsh(G)
    if g[0] <= FOLD_RATIO * FOLD_RATIO * g[-1]:
        return FOLDED, it, dist, 0.0
    Li = np.linalg.inv(np.linalg.cholesky(G))
    cond = np.linalg.eigvalsh(Li @ H @ Li.T)[0]
    J[:, :] = np.linalg.solve(H, DX.T)
    if not converged:
        return NOT_CONVERGED, it, dist, cond
    if cond < min_cond or cond * min_cond > 1.0:
        return NEAR_FOCAL, it, dist, cond
    return OK, it, dist, cond
