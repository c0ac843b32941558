"""Out-of-sample extensions: coordinates of new points from a fitted embedding (``transform``).

* :func:`barycentric_weights`, :func:`lle_extension` - LLE / MLLE (Roweis & Saul 2000, eq. 2;
  Saul & Roweis 2003, §6.1; Bengio et al. 2004, §4): a new x is reconstructed from its k nearest
  training points, x ~ sum_j w_j x_j with sum_j w_j = 1, and mapped to y = sum_j w_j y_j.
* :func:`mds_extension` - Isomap (landmark MDS of de Silva & Tenenbaum 2004; the Nystrom formula
  of Bengio et al. 2004, §4): y = -1/2 Lambda^{-1/2} V^T (delta_x^2 - mu), delta_x the geodesic
  distances from x to the training points, mu_j = (1/N) sum_k delta_G(x_j, x_k)^2.
* :func:`stress_placement` - NLIE: y minimises the NLIE stress of x's pairs with its k_G
  geodesically nearest training points, the training embedding held fixed.
"""
from __future__ import annotations

import numpy as np


def barycentric_weights(Z: np.ndarray, reg: float) -> np.ndarray:
    """Reconstruction weights of M points from their k neighbours (Roweis & Saul 2000, eq. 2).

    ``Z`` (M, k, D): the offsets x_j - x of the neighbours. With the local Gram matrix
    C_jl = (x_j - x).(x_l - x), solve (C + r I) w = 1 and normalise, sum_j w_j = 1:
    w minimises |x - sum_j w_j x_j|^2 + r |w|^2 under sum_j w_j = 1. r = reg * trace(C) (reg
    when trace(C) = 0), the regulariser of Roweis & Saul's code and of scikit-learn's LLE, needed
    when k > D makes C singular. Returns (M, k); affine functions of x are reproduced when r -> 0.
    """
    C = np.einsum("mjd,mld->mjl", Z, Z)
    k = Z.shape[1]
    tr = np.trace(C, axis1=1, axis2=2)
    r = np.where(tr > 0, reg * tr, reg)
    C[:, np.arange(k), np.arange(k)] += r[:, None]
    w = np.linalg.solve(C, np.ones((Z.shape[0], k, 1)))[..., 0]
    return w / w.sum(axis=1, keepdims=True)


def lle_extension(Y: np.ndarray, tree, X: np.ndarray, n_neighbors: int, reg: float) -> np.ndarray:
    """LLE coordinates of new points ``X`` (M, D): y = sum_j w_j y_j over the k nearest training
    points x_j (``tree``: cKDTree of the training points, ``Y`` their embedding).

    A point equal to a training point x_i is reconstructed from the k nearest *other* training
    points, i.e. from x_i's own LLE neighbourhood and weights W_i: its image is
    sum_j W_ij y_j, which LLE makes close to y_i (the residual |y_i - sum_j W_ij y_j| is what
    the LLE eigenproblem minimises) but not equal to it.
    """
    k = int(n_neighbors)
    dist, idx = tree.query(X, k=k + 1)
    same = dist[:, 0] == 0.0
    nb = np.where(same[:, None], idx[:, 1:], idx[:, :k])
    w = barycentric_weights(tree.data[nb] - X[:, None, :], reg)
    return np.einsum("mk,mkd->md", w, Y[nb])


def mds_extension(D_new: np.ndarray, mean_sq: np.ndarray, projector: np.ndarray) -> np.ndarray:
    """Landmark-MDS / Nystrom placement y = -1/2 (delta_x^2 - mu) P of new points.

    ``D_new`` (M, N): geodesic distances from the new points to the N training points;
    ``mean_sq`` (N,): mu_j = (1/N) sum_k delta_G(x_j, x_k)^2; ``projector`` (N, d):
    P = V Lambda^{-1/2} (columns with the signs of the embedding, zero for Lambda <= 0).
    For a training point, delta_x = delta_G(x_i, .) and, since B = -1/2 J Delta^2 J has
    B V = V Lambda with V^T 1 = 0, y = Lambda^{-1/2} V^T B e_i = Lambda^{1/2} V^T e_i = y_i:
    the training embedding is reproduced exactly (de Silva & Tenenbaum 2004, §3).
    """
    return -0.5 * (np.square(D_new) - mean_sq) @ projector


def _local_stress(y, Yn, g, alpha, order):
    """e(y) = 1/2 sum_j [alpha (r_j/g_j - 1)^2 + (1 - alpha)(g_j/r_j - 1)^2], r_j = |y - y_j|,
    per row; with ``order`` 2 also its gradient and Hessian (true, and convex part)."""
    q = y[:, None, :] - Yn                                  # (M, k, d)
    r = np.sqrt(np.einsum("mkd,mkd->mk", q, q))
    with np.errstate(divide="ignore", invalid="ignore"):
        e1 = r / g - 1.0
        E = 0.5 * alpha * np.sum(e1 * e1, axis=1)
        if alpha < 1.0:
            e2 = g / r - 1.0
            E = E + 0.5 * (1.0 - alpha) * np.sum(e2 * e2, axis=1)
        if order == 0:
            return np.where(np.isfinite(E), E, np.inf)
        fp = alpha * e1 / g                                  # f'(r)
        fpp = alpha / g ** 2 + 0.0 * r                     # f''(r)
        if alpha < 1.0:
            fp = fp - (1.0 - alpha) * e2 * g / r ** 2
            fpp = fpp + (1.0 - alpha) * (3 * g ** 2 / r ** 4 - 2 * g / r ** 3)
        a = fp / r
        b = (fpp - a) / r ** 2
    grad = np.einsum("mk,mkd->md", a, q)
    d = y.shape[1]
    eye = np.eye(d)

    def hess(a_, b_):
        return (a_.sum(axis=1)[:, None, None] * eye
                + np.einsum("mk,mki,mkj->mij", b_, q, q))

    H = hess(a, b)
    ac = np.maximum(a, 0.0)
    H_convex = hess(ac, (np.maximum(fpp, 0.0) - ac) / r ** 2)
    return E, grad, H, H_convex


def stress_placement(Y: np.ndarray, idx: np.ndarray, g: np.ndarray, alpha: float,
                     y0: np.ndarray, *, tol: float = 1e-6, max_iter: int = 50) -> np.ndarray:
    """NLIE coordinates of new points: y minimises the NLIE stress (thesis Appendix C)

        e(y) = 1/2 sum_{j in N(x)} [alpha (|y - y_j|/g_j - 1)^2 + (1 - alpha)(g_j/|y - y_j| - 1)^2]

    over the k_G geodesically nearest training points N(x) (``idx`` (M, k), distances ``g``),
    the training embedding ``Y`` held fixed: the same energy as the fit, for one more point.
    Newton's method per point from ``y0`` with an Armijo backtracking line search, on the true
    d x d Hessian where it is positive definite and on its convex part (pair terms clipped to
    positive semidefinite, as in ``nlie_stress``) elsewhere; a point stops when
    |grad e| <= tol k / median(g) (the test of ``nlie.gradient_tolerance`` for one point) or
    its step stalls. Each point is placed independently of the others.

    A new point equal to a training point x_i (g = 0 for j = i) is placed at y_i: the limit of
    the minimiser as x -> x_i, since the term alpha (|y - y_i|/g_i - 1)^2 pins |y - y_i| to
    g_i -> 0.
    """
    y = np.array(y0, dtype=np.float64, copy=True)
    same = g[:, 0] == 0.0
    y[same] = Y[idx[same, 0]]
    active = np.flatnonzero(~same)
    if active.size == 0:
        return y
    Yn_all, g_all = Y[idx], g
    gtol = tol * g.shape[1] / np.median(g_all, axis=1)
    for _ in range(max_iter):
        Yn, ga = Yn_all[active], g_all[active]
        E, grad, H, Hc = _local_stress(y[active], Yn, ga, alpha, order=2)
        finite = np.isfinite(H).all(axis=(1, 2)) & np.isfinite(Hc).all(axis=(1, 2))
        if not finite.all():                 # y on some y_j (r = 0): no direction; stop there
            active, E, grad, H, Hc, Yn, ga = (v[finite] for v in (active, E, grad, H, Hc, Yn, ga))
            if active.size == 0:
                break
        done = np.linalg.norm(grad, axis=1) <= gtol[active]
        lam = np.linalg.eigvalsh(H)[:, 0]
        use = np.where((lam > 0)[:, None, None], H, Hc)
        shift = 1e-12 * np.abs(np.trace(use, axis1=1, axis2=2)) + 1e-300
        use = use + shift[:, None, None] * np.eye(y.shape[1])
        step = -np.linalg.solve(use, grad[..., None])[..., 0]
        slope = np.einsum("md,md->m", grad, step)
        t = np.ones(active.size)
        ok = np.zeros(active.size, bool)
        for _ls in range(40):
            trial = _local_stress(y[active] + t[:, None] * step, Yn, ga, alpha, order=0)
            ok = done | (trial <= E + 1e-4 * t * slope)
            if ok.all():
                break
            t = np.where(ok, t, 0.5 * t)
        move = np.where((ok & ~done)[:, None], t[:, None] * step, 0.0)   # done: stay
        y[active] += move
        stalled = ~ok | (np.linalg.norm(move, axis=1) <= 1e-14 * np.median(ga, axis=1))
        active = active[~(done | stalled)]
        if active.size == 0:
            break
    return y
