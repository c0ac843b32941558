"""Nonlinear Locally Isometric Embedding (NLIE), thesis Appendix C (L3127-3160).

Minimises the sparse stress alpha E1 + (1 - alpha) E2 over the k_G geodesically nearest
neighbours of every point (``nlie_stress``), seeded by Isomap (landmark Isomap for large N),
first with L-BFGS to a coarse tolerance, then with line-search Newton using the analytic sparse
Hessian and preconditioned CG. Memory and time per iteration are linear in N k_G.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.errors import ConfigError

from .base import EmbedderBase
from .checks import check_float, check_graph_params, check_int, check_points
from .geodesics import geodesic_neighbors, pairs_from_neighbors
from .isomap import landmark_isomap_embedding
from .neighbor_graph import connected_neighbor_graph
from .newton_cg import newton_line_search
from .nlie_stress import StressHessian, stress_energy, stress_energy_grad
from .quality import stress_on_pairs


def _block_jacobi(blocks: np.ndarray, shift: float):
    """Preconditioner applying the inverse of the (shifted) d x d diagonal blocks."""
    n, d, _ = blocks.shape
    B = blocks + shift * np.eye(d)
    lam = np.linalg.eigvalsh(B)
    bad = lam[:, 0] <= 0                       # non-PD block: use |diag| instead
    if bad.any():
        B[bad] = np.abs(np.einsum("nii->ni", B[bad]))[:, :, None] * np.eye(d) + shift * np.eye(d)
    Binv = np.linalg.inv(B)

    def apply(r):
        return np.einsum("nij,nj->ni", Binv, r.reshape(n, d)).ravel()

    return apply


def nlie_optimize(Y0, pi, pj, g, w, alpha, *, tol=1e-6, max_iter=50, lbfgs_tol=1e-5,
                  lbfgs_max_iter=300):
    """Minimise the NLIE stress from ``Y0`` (N, d); return (Y, info dict)."""
    from scipy.optimize import minimize

    n, d = Y0.shape
    gbar = float(np.median(g))
    kbar = max(1.0, 2.0 * float(w.sum()) / n)      # mean number of neighbours per point
    grad_tol = tol * kbar / gbar                   # |dE/dq| scale: k_G * (relative error) / g

    def fg(x):
        E, G = stress_energy_grad(x.reshape(n, d), pi, pj, g, w, alpha)
        return E, G.ravel()

    def f(x):
        return stress_energy(x.reshape(n, d), pi, pj, g, w, alpha)

    res = minimize(fg, Y0.ravel(), jac=True, method="L-BFGS-B",
                   options={"maxiter": lbfgs_max_iter, "ftol": lbfgs_tol,
                            "gtol": 100 * grad_tol,
                            "maxcor": 10})
    pattern = StressHessian(n, d, pi, pj)

    def hess(x):
        H = pattern.assemble(x.reshape(n, d), pi, pj, g, w, alpha)
        blocks = pattern.diagonal_blocks()
        scale = float(np.einsum("nii->", blocks)) / (n * d)
        return (lambda v: H @ v), _block_jacobi(blocks, 1e-10 * scale), scale

    out = newton_line_search(fg, f, hess, res.x, grad_tol=grad_tol, max_iter=max_iter)
    info = {"lbfgs_iter": int(res.nit), "lbfgs_message": str(res.message), "newton_iter": out.n_iter, "cg_iter": out.cg_iters,
            "objective": out.fun, "grad_max": out.grad_norm, "grad_tol": grad_tol,
            "converged": out.converged}
    return out.x.reshape(n, d), info


@dataclass
class NLIEConfig:
    n_components: int = 2
    n_neighbors: Optional[int] = 12
    radius: Optional[float] = None
    n_stress_neighbors: int = 50
    alpha: float = 0.99
    tol: float = 1e-6
    max_iter: int = 50
    lbfgs_tol: float = 1e-5
    lbfgs_max_iter: int = 300
    seed_landmarks: int = 1000
    random_state: int = 0
    aic: bool = False
    aic_neighbors: Optional[int] = None


class NLIE(EmbedderBase):
    """Nonlinear Locally Isometric Embedding (sparse geodesic stress, L-BFGS then Newton)."""

    Config: ClassVar[type] = NLIEConfig
    description: ClassVar[str] = "NLIE: sparse geodesic stress minimisation seeded by Isomap."
    parameter_constraints: ClassVar[dict] = {
        "n_neighbors": "integer >= 1: k-NN graph for geodesic distances (or radius)",
        "n_stress_neighbors": "integer k_G >= 1, < N: neighbours in the stress (thesis 200-1000)",
        "alpha": "float in (0, 1]: weight of E1 (thesis 0.99-0.999 for d > 1, 1 for d = 1)",
        "tol": "float > 0: Newton stop, max |grad| <= tol * k_G / median geodesic distance",
        "lbfgs_tol": "float > 0: coarse L-BFGS stop on the relative decrease of E per iteration",
        "seed_landmarks": "integer >= d + 1: landmarks of the Isomap seed (full Isomap if >= N)",
    }

    def __init__(self, *, n_components: int = 2, n_neighbors: Optional[int] = 12,
                 radius: Optional[float] = None, n_stress_neighbors: int = 50,
                 alpha: float = 0.99, tol: float = 1e-6, max_iter: int = 50,
                 lbfgs_tol: float = 1e-5, lbfgs_max_iter: int = 300, seed_landmarks: int = 1000,
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
        self.seed_landmarks = seed_landmarks
        self.random_state = random_state
        self.aic = aic
        self.aic_neighbors = aic_neighbors

    def _embed(self, X) -> np.ndarray:
        X = check_points(X, min_points=2)
        n = X.shape[0]
        check_graph_params(self.n_neighbors, self.radius, n)
        d = check_int("n_components", self.n_components, low=1)
        if d >= X.shape[1]:
            raise ConfigError(f"n_components={d} must be below the ambient dimension {X.shape[1]}.")
        kG = check_int("n_stress_neighbors", self.n_stress_neighbors, low=1, high=n - 1,
                       fix=f"With {n} points use at most {n - 1}; the thesis uses 200-1000.")
        alpha = check_float("alpha", self.alpha, low=0.0, high=1.0, low_open=True,
                            fix="Use 0.99-0.999 for d > 1 and 1 for d = 1.")
        check_float("tol", self.tol, low=0.0, low_open=True)
        check_float("lbfgs_tol", self.lbfgs_tol, low=0.0, low_open=True)
        check_int("max_iter", self.max_iter, low=0)
        check_int("lbfgs_max_iter", self.lbfgs_max_iter, low=0)
        n_land = check_int("seed_landmarks", self.seed_landmarks, low=d + 1)
        G = connected_neighbor_graph(X, self.n_neighbors, self.radius)
        idx, dist = geodesic_neighbors(G, kG)
        pi, pj, g, w = pairs_from_neighbors(idx, dist)
        Y0 = landmark_isomap_embedding(X, d, self.n_neighbors, self.radius,
                                       n_landmarks=n_land, seed=self.random_state, graph=G)
        self.embedding_seed_ = Y0
        Y, info = nlie_optimize(Y0, pi, pj, g, w, alpha, tol=self.tol, max_iter=self.max_iter,
                                lbfgs_tol=self.lbfgs_tol, lbfgs_max_iter=self.lbfgs_max_iter)
        self.n_iter_ = info["lbfgs_iter"] + info["newton_iter"]
        self.converged_ = info["converged"]
        self.objective_ = info["objective"]
        self.info_ = info
        k = self._aic_neighbors()
        nb = (idx[:, :k], dist[:, :k]) if k <= kG else geodesic_neighbors(G, k)
        self.stress_ = stress_on_pairs(Y, *nb)   # E_S as in Table 1 (k = aic_neighbors)
        return Y
