"""Affine isometric correction (AIC), thesis Appendix E.1 (and §3, Table 1).

Given an embedding Y = {y_a} (N, d) from any NLDR method, find the symmetric positive-definite
d x d matrix A minimising the stress (thesis L3567-3570, L3655; the reading of the printed
formula is argued in ``quality``)

    E_S(A) = 1/2 sum_a sum_{b in N(a)} ((|A (y_a - y_b)| - g_ab) / g_ab)^2,

with N(a) the k nearest neighbours of x_a and g_ab their geodesic (graph) distance (= |x_a - x_b|
for a k-NN edge). The thesis minimises over d x d matrices T with det T > 0 and notes that by
the polar decomposition the SPD factor suffices (L3571): |R U v| = |U v|. A is parametrised by
its d(d+1)/2 upper-triangular entries t; Newton's method with an Armijo backtracking line search
that rejects steps leaving the SPD cone (thesis: L-BFGS, then Newton with line search, L3665;
"converges very rapidly", L2095). The Hessian is modified (its eigenvalues are taken in
absolute value and floored) where it is not positive definite.
Start: A0 = s I with the best uniform scale s = sum(r/g) / sum((r/g)^2), the exact minimiser of
E_S over A = s I (the thesis starts at T0 = I, L3665). This matters for LLE/MLLE, whose
unit-covariance output (thesis L1873) has an arbitrary scale: the optimum is then far from I
(A ~ 0.4 I on the unit quarter sphere, ~4 I on a sphere of radius 10). The result is invariant
under Y -> Y B for any invertible B and equals the minimum over all 2 x 2 T found by a
derivative-free search (checked in the tests), so the reported optimum is the global one.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pointatlas.errors import ConfigError, InputError

from .geodesics import geodesic_neighbors
from .neighbor_graph import connected_neighbor_graph
from .quality import stress_on_pairs


@dataclass
class AICResult:
    """Outcome of :func:`affine_isometric_correction`."""

    matrix: np.ndarray          # (d, d) SPD matrix A
    embedding: np.ndarray       # (N, d): ybar + (Y - ybar) A
    stress_before: float        # E_S(I)
    stress_after: float         # E_S(A)
    n_iter: int
    converged: bool


def symmetric_basis(d: int) -> np.ndarray:
    """(m, d, d) basis of symmetric matrices, m = d(d+1)/2: E_ii, and E_ij + E_ji for i < j."""
    out = []
    for i in range(d):
        for j in range(i, d):
            B = np.zeros((d, d))
            B[i, j] = B[j, i] = 1.0
            out.append(B)
    return np.array(out)


def aic_energy(t: np.ndarray, dY: np.ndarray, g: np.ndarray, basis: np.ndarray, order: int = 2):
    """Stress E_S(A(t)), its gradient (m,) and Hessian (m, m) over pairs.

    ``dY``: (P, d) embedded differences y_a - y_b; ``g``: (P,) geodesic distances.
    With M_p = [B_k dy_p]_k (d, m), z = M t, r = |z|:
    grad = sum (r - g)/g^2 M^T z / r,
    Hess = sum [ M^T z z^T M / (g^2 r^2) + (r - g)/(g^2 r) (M^T M - M^T z z^T M / r^2) ].
    """
    M = np.einsum("kij,pj->pik", basis, dY)           # (P, d, m)
    z = np.einsum("pik,k->pi", M, t)
    r = np.sqrt(np.einsum("pi,pi->p", z, z))
    res = (r - g) / g
    E = 0.5 * float(np.sum(res * res))
    if order == 0:
        return E
    r_safe = np.where(r > 0, r, 1.0)
    eta = np.einsum("pik,pi->pk", M, z) / r_safe[:, None]   # dr/dt
    grad = np.einsum("p,pk->k", res / g, eta)
    if order == 1:
        return E, grad
    c1 = 1.0 / (g * g)
    c2 = res / (g * r_safe)
    MtM = np.einsum("pik,pil->pkl", M, M)
    H = np.einsum("p,pk,pl->kl", c1 - c2, eta, eta) + np.einsum("p,pkl->kl", c2, MtM)
    return E, grad, H


def _is_spd(A: np.ndarray) -> bool:
    try:
        np.linalg.cholesky(A)
        return True
    except np.linalg.LinAlgError:
        return False


def aic_on_pairs(Y: np.ndarray, idx: np.ndarray, dist: np.ndarray, *, tol: float = 1e-10,
                 max_iter: int = 100) -> AICResult:
    """AIC for given neighbourhoods ``idx``/``dist`` ((N, k) indices and geodesic distances)."""
    Y = np.asarray(Y, float)
    n, d = Y.shape
    dY = (Y[:, None, :] - Y[idx]).reshape(-1, d)
    g = dist.ravel()
    basis = symmetric_basis(d)
    iu = np.triu_indices(d)
    r0 = np.linalg.norm(dY, axis=1)
    if not np.all(r0 > 0):
        raise InputError("the embedding maps neighbouring points onto each other; AIC cannot fix a "
                         "collapsed embedding. Use another embedder or more neighbours.")
    s = np.sum(r0 / g) / np.sum((r0 / g) ** 2)
    t = (s * np.eye(d))[iu]
    E0 = stress_on_pairs(Y, idx, dist)
    E, grad, H = aic_energy(t, dY, g, basis)
    converged = False
    it = 0
    for it in range(1, max_iter + 1):
        lam, V = np.linalg.eigh(H)
        lam = np.maximum(np.abs(lam), 1e-12 * max(np.abs(lam).max(), 1e-300))
        step = -V @ ((V.T @ grad) / lam)
        slope = float(grad @ step)
        alpha = 1.0
        accepted = False
        while alpha > 1e-12:
            t_new = t + alpha * step
            A_new = np.zeros((d, d))
            A_new[iu] = t_new
            A_new = A_new + np.triu(A_new, 1).T
            if _is_spd(A_new):
                E_new = aic_energy(t_new, dY, g, basis, order=0)
                if E_new <= E + 1e-4 * alpha * slope:
                    accepted = True
                    break
            alpha *= 0.5
        if not accepted:
            converged = True   # no further decrease possible at machine precision
            break
        dE = E - E_new
        t = t_new
        E, grad, H = aic_energy(t, dY, g, basis)
        if dE <= tol * max(E, 1e-300) or np.linalg.norm(grad) <= tol * max(E, 1.0):
            converged = True
            break
    A = np.zeros((d, d))
    A[iu] = t
    A = A + np.triu(A, 1).T
    mean = Y.mean(axis=0)
    Yc = mean + (Y - mean) @ A
    return AICResult(A, Yc, E0, stress_on_pairs(Yc, idx, dist), it, converged)


def affine_isometric_correction(Y, X=None, *, n_neighbors: int = 12, neighbors=None,
                                tol: float = 1e-10, max_iter: int = 100) -> AICResult:
    """Best SPD matrix A making ``Y`` A as isometric as possible to ``X`` (thesis Appendix E.1).

    Parameters
    ----------
    Y : (N, d) embedding.
    X : (N, D) original points; geodesic distances to each point's ``n_neighbors`` nearest are
        computed on the ``n_neighbors``-NN graph. Not needed if ``neighbors`` is given.
    neighbors : optional ``(idx, dist)``, (N, k) neighbour indices and geodesic distances.
    """
    Y = np.asarray(Y, float)
    if Y.ndim != 2:
        raise InputError(f"embedding must be a 2-D array (n_points, d); got shape {Y.shape}.")
    if neighbors is None:
        if X is None:
            raise ConfigError("give the original points X or neighbors=(idx, dist) to AIC.")
        X = np.asarray(X, float)
        if X.shape[0] != Y.shape[0]:
            raise InputError(f"X has {X.shape[0]} points but the embedding has {Y.shape[0]}; "
                             "pass the points that were embedded.")
        neighbors = geodesic_neighbors(connected_neighbor_graph(X, n_neighbors), n_neighbors)
    idx, dist = neighbors
    return aic_on_pairs(Y, idx, dist, tol=tol, max_iter=max_iter)
