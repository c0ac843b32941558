"""SandCV: smooth, nonlinear, data-driven collective variables (Hashemian, Millán & Arroyo,
J. Chem. Phys. 139 (2013) 214101).

Training: aligned configurations z_i ∈ R^D (D = 3 × CV atoms, nm) with embedding coordinates
ξ_i ∈ R^d from any embedder; the manifold X(ξ) = Σ_a p_a(ξ) P_a is the LME least-squares fit of
:class:`pointatlas_reduction.slow_manifold.SlowManifold` (nodes on a binned subsample of the
embedding). Evaluation of a new configuration x (the CV atoms' raw positions, nm): superpose
on the reference (:mod:`.kabsch`), project z on the manifold (:mod:`.projection`), and pull
∂ξ/∂z back to ∂ξ/∂x through the optimal rotation. ξ is invariant to rigid motions of the
molecule by construction; ``distance`` |X(ξ) − z| (nm) says how far x is from what the
training ensemble sampled; ``status`` is non-zero where the value must not be used.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba as nb
import numpy as np

from pointatlas.errors import InputError

from .kabsch import pull_back, superpose
from .projection import OK, STATUS_NAMES, hull_equations, project, scratch


@nb.njit(cache=True)
def _evaluate(x, ref, wts, nodes, beta, r2, P, hull, lme_tol, lme_max_iter, tol, max_iter,
              min_cond, xi, grad):
    """ξ (overwriting the start ``xi``) and ∂ξ/∂x into grad (d, n, 3):
    (status, steps, distance, conditioning)."""
    n = x.shape[0]
    d = xi.shape[0]
    z = np.empty((n, 3))
    R = np.empty((3, 3))
    superpose(x, ref, wts, z, R)
    J = np.empty((d, 3 * n))
    w = scratch(nodes.shape[0], d)
    status, steps, dist, cond = project(z.ravel(), xi, nodes, beta, r2, P, hull, lme_tol,
                                        lme_max_iter, tol, max_iter, min_cond, w, J)
    if status == OK:
        g = np.empty((n, 3))
        out = np.empty((n, 3))
        for k in range(d):
            for i in range(n):
                for a in range(3):
                    g[i, a] = J[k, 3 * i + a]
            pull_back(g, z, R, ref, wts, out)
            grad[k] = out
    return status, steps, dist, cond


@dataclass
class CVValue:
    """ξ (d,), ∂ξ/∂x (d, n_atoms, 3) in 1/nm, distance to the manifold (nm), Newton steps,
    status (0 = ok; else see ``reason``), conditioning c (1 on the manifold, 0 at its focal
    set; :mod:`.projection`)."""
    xi: np.ndarray
    gradient: np.ndarray
    distance: float
    steps: int
    status: int
    conditioning: float

    @property
    def ok(self) -> bool:
        return self.status == OK

    @property
    def reason(self) -> str:
        return STATUS_NAMES[self.status]


class SandCV:
    """ξ(x) and ∂ξ/∂x of configurations of the CV atoms on a manifold learnt from them.

    Parameters: ``approximant`` (a fitted-on-demand LME plugin), ``n_bins`` of the node
    binning, ``tol`` (Newton stops when a step is shorter than tol × the embedding's extent),
    ``max_iter`` Newton steps, ``min_conditioning``: configurations whose conditioning c is
    below it are flagged (status NEAR_FOCAL) and get no gradient.
    """

    def __init__(self, approximant, n_bins: int = 40, tol: float = 1e-10, max_iter: int = 20,
                 min_conditioning: float = 0.1):
        self.approximant, self.n_bins = approximant, int(n_bins)
        self.tol, self.max_iter = float(tol), int(max_iter)
        self.min_conditioning = float(min_conditioning)

    def fit(self, Z, Q, reference, weights=None):
        """Aligned frames Z (N, n, 3) in nm, embedding Q (N, d), the reference (n, 3) they were
        superposed on (centred here), alignment weights (uniform by default)."""
        from pointatlas_reduction.slow_manifold import SlowManifold

        Z = np.asarray(Z, dtype=np.float64)
        if Z.ndim != 3 or Z.shape[2] != 3:
            raise InputError(f"aligned frames of shape {Z.shape}: give (frames, atoms, 3).")
        n = Z.shape[1]
        w = np.full(n, 1.0 / n) if weights is None else np.asarray(weights, float)
        self.weights_ = np.ascontiguousarray(w / w.sum())
        ref = np.asarray(reference, dtype=np.float64)
        self.reference_ = np.ascontiguousarray(ref - self.weights_ @ ref)
        self.manifold_ = SlowManifold(self.approximant, self.n_bins).fit(Z.reshape(len(Z), -1),
                                                                         Q)
        basis = self.manifold_.basis_
        self.nodes_ = np.ascontiguousarray(basis.nodes_)
        self.beta_ = np.ascontiguousarray(basis.beta_)
        self.r2_ = np.ascontiguousarray(basis.radius_ ** 2)
        self.P_ = np.ascontiguousarray(self.manifold_.P_)
        self.hull_ = hull_equations(self.nodes_)
        self.lme_tol_ = float(basis.newton_tol) * basis.h_ref_
        self.lme_max_iter_ = int(basis.max_iter)
        self.step_tol_ = self.tol * float(np.max(np.ptp(self.nodes_, axis=0)))
        self.Q_ = np.asarray(Q, dtype=np.float64)
        self.Z_ = Z.reshape(len(Z), -1)
        return self

    @property
    def dim(self) -> int:
        return self.nodes_.shape[1]

    @property
    def n_atoms(self) -> int:
        return self.reference_.shape[0]

    def start(self, x) -> np.ndarray:
        """ξ of the training frame nearest to x after superposition (a cold start)."""
        z = np.empty_like(self.reference_)
        superpose(np.ascontiguousarray(x, dtype=np.float64), self.reference_, self.weights_, z,
                  np.empty((3, 3)))
        i = int(np.argmin(np.sum((self.Z_ - z.ravel()) ** 2, axis=1)))
        return self.Q_[i].copy()

    @staticmethod
    def predict(previous: CVValue, x_previous, x) -> np.ndarray:
        """A warm start for x from the value at a nearby x_previous (the previous MD step):
        ξ_prev + ∂ξ/∂x (x − x_prev), first-order accurate (the previous ξ alone is zeroth)."""
        g = previous.gradient
        return previous.xi + g.reshape(g.shape[0], -1) @ (np.asarray(x) - x_previous).ravel()

    def __call__(self, x, xi_start=None, tol: float | None = None) -> CVValue:
        """ξ(x) of the CV atoms' positions x (n, 3) in nm, warm-started from ``xi_start``;
        ``tol`` overrides the relative Newton tolerance (a finite-difference reference needs
        a tighter one than MD)."""
        x = np.ascontiguousarray(x, dtype=np.float64)
        if x.shape != self.reference_.shape:
            raise InputError(f"configuration of shape {x.shape}, the CV was trained on "
                             f"{self.reference_.shape}: pass the CV atoms' positions only.")
        xi = self.start(x) if xi_start is None else np.array(xi_start, dtype=np.float64)
        grad = np.zeros((self.dim, self.n_atoms, 3))
        status, steps, dist, cond = _evaluate(
            x, self.reference_, self.weights_, self.nodes_, self.beta_, self.r2_, self.P_,
            self.hull_, self.lme_tol_, self.lme_max_iter_,
            self.step_tol_ if tol is None else tol * self.step_tol_ / self.tol, self.max_iter,
            self.min_conditioning, xi, grad)
        return CVValue(xi, grad, float(dist), int(steps), int(status), float(cond))
