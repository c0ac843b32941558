"""Nonlinear Locally Isometric Embedding (NLIE), thesis Appendix C (L3127-3160).

Minimises the sparse stress alpha E1 + (1 - alpha) E2 over the k_G geodesically nearest
neighbours of every point (``nlie_stress``), seeded by Isomap (landmark Isomap for large N),
with line-search Newton using the analytic sparse Hessian (``newton_cg``). The thesis first
iterates L-BFGS to a coarse tolerance; that stage is kept (``lbfgs_max_iter``) but off by
default: from the Isomap seed, whose local distortions make the Hessian indefinite, Newton steps
on the convex part of the Hessian (positive-semidefinite pair blocks) remove them in a few unit
steps, while L-BFGS, slowed by the 1/g^2 stiffness of the closest pairs, needs hundreds of
iterations (swiss roll, N = 10 000, k_G = 200: 300 L-BFGS iterations did not get as far as
three Newton steps). CG is preconditioned by a sparse LU of the Hessian of the few nearest pairs
of every point (``NearPairPreconditioner``), which keeps the CG count per Newton step about
constant in N. Memory and time per iteration are linear in N k_G.

Convergence: max_i |dE_S/dq_i| <= tol * kbar / median(g) (``gradient_tolerance``), kbar the mean
number of pairs per point: the largest force on a point is at most that of all its pairs being
off by a relative length error ``tol`` in the same direction. Dimensionless, the same for all N.

Out of sample (``transform``, :func:`.out_of_sample.stress_placement`): a new point x joins the
training graph by one-way edges to its graph neighbours (``neighbor_graph.attach_points``); its
k_G geodesically nearest training points and distances g_j give the NLIE stress of its pairs,
minimised over y alone with the training embedding fixed, from the barycentric (LLE-weight)
combination of its nearest neighbours' coordinates. A training point is placed on its own
embedding, the limit of that minimiser (g_i -> 0), so ``transform`` reproduces it exactly.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.constraints import Interval
from pointatlas.errors import ConfigError

from .base import EmbedderBase
from .checks import (AIC, COMPONENTS, GRAPH, check_components, check_graph_fits, check_one_graph,
                     check_points)
from .geodesics import geodesic_neighbors, pairs_from_neighbors
from .isomap import landmark_isomap_embedding
from .neighbor_graph import attach_points, connected_neighbor_graph
from .newton_cg import newton_line_search
from .nlie_stress import (NearPairPreconditioner, hessian_diagonal_blocks, hessian_matvec,
                          near_pairs, pair_curvatures, stress_energy, stress_energy_grad)
from .out_of_sample import barycentric_weights, stress_placement
from .quality import stress_on_pairs


def _block_jacobi(blocks: np.ndarray, shift: float):
    """Fallback preconditioner: inverse of the (shifted) d x d diagonal blocks."""
    n, d, _ = blocks.shape
    Binv = np.linalg.inv(blocks + shift * np.eye(d))

    def apply(r):
        return np.einsum("nij,nj->ni", Binv, r.reshape(n, d)).ravel()

    return apply


class StressProblem:
    """E_S, its gradient and its Hessian (as matvec + preconditioner) on flat vectors x = Q.ravel().

    The preconditioner (``NearPairPreconditioner`` on the ``precond_neighbors`` nearest pairs of
    every point) is built once per Newton point from the convex part of the Hessian.
    """

    def __init__(self, n, d, pi, pj, g, w, alpha, precond_neighbors: int = 8):
        self.n, self.d = n, d
        self.pi, self.pj, self.g, self.w, self.alpha = pi, pj, g, w, alpha
        self.near = near_pairs(pi, pj, g, n, max(1, min(precond_neighbors, n - 1)))
        self.a, self.b = np.empty(pi.size), np.empty(pi.size)
        self.ac, self.bc = np.empty(pi.size), np.empty(pi.size)
        self._x = None

    def fun_grad(self, x):
        E, G = stress_energy_grad(x.reshape(self.n, self.d), self.pi, self.pj, self.g, self.w,
                                  self.alpha)
        return E, G.ravel()

    def fun(self, x):
        return stress_energy(x.reshape(self.n, self.d), self.pi, self.pj, self.g, self.w,
                             self.alpha)

    def hess(self, x, convex: bool):
        n, d = self.n, self.d
        Q = x.reshape(n, d)
        args = (Q, self.pi, self.pj, self.g, self.w, self.alpha)
        if self._x is not x:                 # new Newton point: convex part + preconditioner
            self._x = x
            pair_curvatures(*args, convex=True, out=(self.ac, self.bc))
            blocks = hessian_diagonal_blocks(Q, self.pi, self.pj, self.ac, self.bc)
            trace = float(np.einsum("nii->", blocks))
            self.shift = 1e-10 * trace / (n * d)
            try:
                self.precond = NearPairPreconditioner(Q, self.pi, self.pj, self.ac, self.bc,
                                                      self.near, trace)
            except (RuntimeError, MemoryError):   # singular factor: point-wise blocks instead
                self.precond = _block_jacobi(blocks, 1e-8 * trace / (n * d))
        if convex:
            a, b = self.ac, self.bc
        else:
            a, b = pair_curvatures(*args, out=(self.a, self.b))

        def matvec(v):
            return hessian_matvec(Q, self.pi, self.pj, a, b, v.reshape(n, d)).ravel() + self.shift * v

        return matvec, self.precond


def gradient_tolerance(g, w, n, tol):
    """Newton stop on max_i |dE_S/dq_i|: tol * kbar / median(g), kbar = mean pairs per point.

    A point whose kbar pairs all have relative length error tol, pulling the same way, feels a
    force kbar * tol / g; the test is dimensionless and the same for every N.
    """
    kbar = max(1.0, 2.0 * float(w.sum()) / n)
    return tol * kbar / float(np.median(g))


def nlie_optimize(Y0, pi, pj, g, w, alpha, *, tol=1e-6, max_iter=50, lbfgs_tol=1e-3,
                  lbfgs_max_iter=0, precond_neighbors=8):
    """Minimise the NLIE stress from ``Y0`` (N, d); return (Y, info dict).

    L-BFGS to the coarse relative tolerance ``lbfgs_tol`` on E (or ``lbfgs_max_iter``
    iterations), then line-search Newton-CG until max_i |dE/dq_i| <= ``gradient_tolerance``.
    """
    from threadpoolctl import threadpool_limits   # a scikit-learn dependency

    with threadpool_limits(limits=1, user_api="blas"):   # BLAS threads only slow O(N) vector ops
        return _nlie_optimize(Y0, pi, pj, g, w, alpha, tol, max_iter, lbfgs_tol, lbfgs_max_iter,
                              precond_neighbors)


def _nlie_optimize(Y0, pi, pj, g, w, alpha, tol, max_iter, lbfgs_tol, lbfgs_max_iter,
                   precond_neighbors):
    from scipy.optimize import minimize

    n, d = Y0.shape
    grad_tol = gradient_tolerance(g, w, n, tol)
    prob = StressProblem(n, d, pi, pj, g, w, alpha, precond_neighbors)

    def converged(G):
        return bool(np.sqrt(np.max(np.sum(G.reshape(n, d) ** 2, axis=1))) <= grad_tol)

    x, nit, msg = Y0.ravel(), 0, "skipped"
    if lbfgs_max_iter > 0:
        res = minimize(prob.fun_grad, x, jac=True, method="L-BFGS-B",
                       options={"maxiter": lbfgs_max_iter, "ftol": lbfgs_tol, "gtol": grad_tol,
                                "maxcor": 10})
        x, nit, msg = res.x, int(res.nit), str(res.message)
    out = newton_line_search(prob.fun_grad, prob.fun, prob.hess, x, converged=converged,
                             max_iter=max_iter)
    gmax = float(np.sqrt(np.max(np.sum(out.grad.reshape(n, d) ** 2, axis=1))))
    info = {"lbfgs_iter": nit, "lbfgs_message": msg, "newton_iter": out.n_iter,
            "newton_convex_steps": out.n_convex, "cg_iter": out.cg_iters, "objective": out.fun,
            "grad_max": gmax, "grad_tol": grad_tol, "converged": out.converged}
    return out.x.reshape(n, d), info


def separate_coincident(Y, pi, pj, seed: int = 0) -> np.ndarray:
    """Y (n, d) with every point that coincides with one of its stress partners (pairs pi,
    pj) moved by 1e-6 of the embedding's extent in a seeded random direction. The stress term
    (|x_ij|/|q_ij| − 1)² is infinite at q_ij = 0, and an Isomap seed maps two points with equal
    geodesic distances to every landmark onto one (a sphere cap sampled along meridians did:
    a ZeroDivisionError inside the stress kernel)."""
    Y = np.array(Y, dtype=np.float64)
    scale = float(np.max(np.ptp(Y, axis=0))) if len(Y) else 1.0
    scale = scale if scale > 0 else 1.0
    rng = np.random.default_rng(int(seed))
    for _ in range(5):
        bad = np.sum((Y[pi] - Y[pj]) ** 2, axis=1) <= (1e-12 * scale) ** 2
        if not bad.any():
            break
        moved = np.unique(pj[bad])
        Y[moved] += 1e-6 * scale * rng.standard_normal((len(moved), Y.shape[1]))
    return Y


@dataclass
class NLIEConfig:
    n_components: int = 2             # below the ambient dimension (checked in fit)
    n_neighbors: Optional[int] = 12   # k-NN graph for geodesic distances (or radius)
    radius: Optional[float] = None
    n_stress_neighbors: int = 50      # k_G < N: neighbours in the stress (thesis 200-1000)
    alpha: float = 0.99               # weight of E1 (thesis 0.99-0.999 for d > 1, 1 for d = 1)
    tol: float = 1e-6                 # Newton stop: max_i |dE/dq_i| <= tol kbar / median g
    max_iter: int = 50                # Newton iterations
    lbfgs_tol: float = 1e-3           # coarse L-BFGS stop on the relative decrease of E
    lbfgs_max_iter: int = 0           # L-BFGS iterations before Newton (0: Newton from the seed)
    precond_neighbors: int = 8        # nearest pairs per point in the Newton-CG preconditioner
    seed_landmarks: int = 1000        # >= d + 1 landmarks of the Isomap seed (full if >= N)
    random_state: int = 0             # seed of the landmark choice
    aic: bool = False
    aic_neighbors: Optional[int] = None

    parameter_constraints: ClassVar[dict[str, list]] = {
        **COMPONENTS, **GRAPH, **AIC,
        "n_stress_neighbors": [Interval(int, 1, None)],
        "alpha": [Interval(float, 0, 1, closed="right")],
        "tol": [Interval(float, 0, None, closed="neither")],
        "max_iter": [Interval(int, 0, None)],
        "lbfgs_tol": [Interval(float, 0, None, closed="neither")],
        "lbfgs_max_iter": [Interval(int, 0, None)],
        "precond_neighbors": [Interval(int, 1, None)],
        "seed_landmarks": [Interval(int, 2, None)],
        "random_state": [Interval(int, 0, None)],
    }


class NLIE(EmbedderBase):
    """Nonlinear Locally Isometric Embedding (sparse geodesic stress, L-BFGS then Newton)."""

    Config: ClassVar[type] = NLIEConfig
    description: ClassVar[str] = "NLIE: sparse geodesic stress minimisation seeded by Isomap."

    def __init__(self, *, n_components: int = 2, n_neighbors: Optional[int] = 12,
                 radius: Optional[float] = None, n_stress_neighbors: int = 50,
                 alpha: float = 0.99, tol: float = 1e-6, max_iter: int = 50,
                 lbfgs_tol: float = 1e-3, lbfgs_max_iter: int = 0, precond_neighbors: int = 8,
                 seed_landmarks: int = 1000,
                 random_state: int = 0, aic: bool = False, aic_neighbors: Optional[int] = None):
        self.n_components = n_components
        self.n_neighbors = n_neighbors
        self.radius = radius
        self.n_stress_neighbors = n_stress_neighbors
        self.alpha = alpha
        self.tol = tol
        self.max_iter = max_iter
        self.lbfgs_tol = lbfgs_tol
        self.lbfgs_max_iter = lbfgs_max_iter
        self.precond_neighbors = precond_neighbors
        self.seed_landmarks = seed_landmarks
        self.random_state = random_state
        self.aic = aic
        self.aic_neighbors = aic_neighbors

    def _check_settings(self) -> None:
        check_one_graph(self.n_neighbors, self.radius)
        if self.seed_landmarks < self.n_components + 1:
            raise ConfigError(
                f"seed_landmarks={self.seed_landmarks!r} is invalid: it must be >= n_components "
                f"+ 1 = {self.n_components + 1} (landmark MDS in dimension d). Pass e.g. "
                "seed_landmarks=1000.")

    def _embed(self, X) -> np.ndarray:
        from scipy.spatial import cKDTree

        d = check_components(self.n_components, X, method="NLIE")
        X = check_points(X, min_points=2)
        n = X.shape[0]
        check_graph_fits(self.n_neighbors, n)
        kG = int(self.n_stress_neighbors)
        if kG > n - 1:
            raise ConfigError(
                f"n_stress_neighbors={kG} is invalid for {n} points: it must be <= {n - 1}. "
                "Lower it; the thesis uses 200-1000 on larger sets.")
        alpha, k_pre = float(self.alpha), int(self.precond_neighbors)
        n_land = int(self.seed_landmarks)
        G = connected_neighbor_graph(X, self.n_neighbors, self.radius)
        idx, dist = geodesic_neighbors(G, kG)
        pi, pj, g, w = pairs_from_neighbors(idx, dist)
        k = self._aic_neighbors()
        nb = (idx[:, :k].copy(), dist[:, :k].copy()) if k <= kG else None
        del idx, dist                          # keep only the pairs during the optimisation
        Y0 = landmark_isomap_embedding(X, d, self.n_neighbors, self.radius,
                                       n_landmarks=n_land, seed=self.random_state, graph=G)
        Y0 = separate_coincident(Y0, pi, pj, self.random_state)
        self.embedding_seed_ = Y0
        Y, info = nlie_optimize(Y0, pi, pj, g, w, alpha, tol=self.tol, max_iter=self.max_iter,
                                lbfgs_tol=self.lbfgs_tol, lbfgs_max_iter=self.lbfgs_max_iter,
                                precond_neighbors=k_pre)
        self.n_iter_ = info["lbfgs_iter"] + info["newton_iter"]
        self.converged_ = info["converged"]
        self.objective_ = info["objective"]
        self.info_ = info
        nb = nb if nb is not None else geodesic_neighbors(G, k)
        self.stress_ = stress_on_pairs(Y, *nb)   # E_S as in Table 1 (k = aic_neighbors)
        self.graph_ = G
        self.tree_ = cKDTree(X)
        return Y

    def _extend(self, X: np.ndarray) -> np.ndarray:
        """Stress placement of new points (module docstring), from ``embedding_raw_``."""
        n, m = self.graph_.shape[0], X.shape[0]
        G = attach_points(self.graph_, self.tree_, X, self.n_neighbors, self.radius)
        idx, g = geodesic_neighbors(G, int(self.n_stress_neighbors), sources=n + np.arange(m))
        Y = self.embedding_raw_
        k0 = min(idx.shape[1], int(self.n_neighbors or 12))   # start: LLE weights (reg 1e-3)
        w = barycentric_weights(self.tree_.data[idx[:, :k0]] - X[:, None, :], 1e-3)
        y0 = np.einsum("mk,mkd->md", w, Y[idx[:, :k0]])
        return stress_placement(Y, idx, g, float(self.alpha), y0, tol=float(self.tol),
                                max_iter=int(self.max_iter))
