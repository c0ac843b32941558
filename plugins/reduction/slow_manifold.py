"""The slow manifold x = X(q) learnt from snapshots (thesis §5.2, Appendix B; Millán & Arroyo,
CMAME 261–262 (2013) 118, §3).

Snapshots x_i ∈ R^D with embedding coordinates q_i ∈ R^d (any embedder). The embedding is
binned on a grid of ``n_bins`` cells per coordinate; the mean q of the snapshots in each
non-empty cell is a node q_a, and the vertices of the embedding's convex hull are nodes too
(the bin means alone would leave the outermost snapshots outside the basis' domain).
Snapshots the basis still cannot reach (on the hull's boundary, where the LME dual has no
solution) are left out of the fit and counted (``n_unfitted_``). Local max-ent basis
functions p_a(q) on the nodes (the ``approximant`` plugin) parametrise the manifold, X(q) = Σ_a p_a(q) P_a, with the nodal
configurations P_a the least-squares fit to the snapshots,

    min_P Σ_i |Σ_a p_a(q_i) P_a − x_i|²  (+ a ridge of 1e-10 × mean diagonal),

so DX(q) = Σ ∇p_a ⊗ P_a and D²X(q) = Σ ∇∇p_a ⊗ P_a follow from the basis derivatives. The
projection q(x) of a configuration is the closest point, min_q |X(q) − x|², by Gauss–Newton
from the embedding coordinate of the nearest snapshot (Appendix B).
"""
from __future__ import annotations

import numpy as np

from pointatlas.errors import InputError


def hull_vertices(Q: np.ndarray) -> np.ndarray:
    """The points of Q at the vertices of its convex hull (the two ends for d = 1)."""
    if Q.shape[1] == 1:
        return Q[[np.argmin(Q[:, 0]), np.argmax(Q[:, 0])]]
    from scipy.spatial import ConvexHull

    return Q[ConvexHull(Q).vertices]


def binned_nodes(Q: np.ndarray, n_bins: int) -> np.ndarray:
    """Mean of the points of each non-empty cell of an n_bins^d grid over the box of Q."""
    Q = np.asarray(Q, dtype=np.float64)
    lo, hi = Q.min(axis=0), Q.max(axis=0)
    cell = np.minimum(((Q - lo) / np.where(hi > lo, hi - lo, 1.0) * n_bins).astype(int),
                      n_bins - 1)
    key = np.ravel_multi_index(cell.T, (n_bins,) * Q.shape[1])
    uniq, inv = np.unique(key, return_inverse=True)
    sums = np.zeros((len(uniq), Q.shape[1]))
    np.add.at(sums, inv, Q)
    return sums / np.bincount(inv)[:, None]


class SlowManifold:
    """X(q), DX(q), D²X(q) and q(x) of snapshots ``X`` (N, D) with embedding ``Q`` (N, d)."""

    def __init__(self, approximant, n_bins: int = 150, ridge: float = 1e-10):
        self.approximant, self.n_bins, self.ridge = approximant, int(n_bins), float(ridge)

    def fit(self, X, Q):
        X = np.asarray(X, dtype=np.float64)
        Q = np.asarray(Q, dtype=np.float64)
        if Q.ndim != 2 or len(Q) != len(X):
            raise InputError(f"{len(X)} snapshots but embedding coordinates of shape "
                             f"{np.shape(Q)}; give one row q per snapshot.")
        if Q.shape[1] >= len(X):
            raise InputError(f"embedding dimension {Q.shape[1]} is not below the number of "
                             f"snapshots {len(X)}; lower n_components or add snapshots.")
        self.nodes_ = np.concatenate([binned_nodes(Q, self.n_bins), hull_vertices(Q)])
        if hasattr(self.approximant, "outside"):
            self.approximant.outside = "flag"
        self.basis_ = self.approximant.fit(self.nodes_)
        b = self.basis_.evaluate(Q, order=0)
        keep = np.ones(len(Q), bool) if b.outside is None else ~np.asarray(b.outside)
        self.n_unfitted_ = int((~keep).sum())
        B = b.take(keep).to_csr(len(self.nodes_))
        X, Q = X[keep], Q[keep]
        A = (B.T @ B).toarray()
        A += self.ridge * np.trace(A) / len(A) * np.eye(len(A))
        self.P_ = np.linalg.solve(A, B.T @ X)                     # (n_nodes, D)
        self.X_, self.Q_ = X, Q
        self.residual_ = float(np.sqrt(np.mean(np.sum((B @ self.P_ - X) ** 2, axis=1))))
        return self

    @property
    def dim(self) -> int:
        return self.nodes_.shape[1]

    def evaluate(self, q, order: int = 0):
        """(X (m, D), DX (m, D, d) if order ≥ 1, D²X (m, D, d, d) if order ≥ 2) at q (m, d)."""
        q = np.atleast_2d(np.asarray(q, dtype=np.float64))
        b = self.basis_.evaluate(q, order=order)
        n = len(self.nodes_)
        out = [b.to_csr(n) @ self.P_]
        if order >= 1:
            out.append(np.stack([b.gradient_csr(n, k) @ self.P_ for k in range(self.dim)],
                                axis=-1))
        if order >= 2:
            from scipy.sparse import csr_matrix

            d = self.dim
            H = np.empty(out[0].shape + (d, d))
            for i in range(d):
                for j in range(d):
                    Hij = csr_matrix((b.hessians[:, i, j], b.indices, b.indptr),
                                     shape=(len(q), n))
                    H[..., i, j] = Hij @ self.P_
            out.append(H)
        return tuple(out) if order else out[0]

    def project(self, x, tol: float = 1e-12, max_iter: int = 50):
        """(q, distance): the closest point of the manifold to x (D,) (Gauss–Newton)."""
        x = np.asarray(x, dtype=np.float64)
        q = self.Q_[np.argmin(np.sum((self.X_ - x) ** 2, axis=1))].copy()
        for _ in range(max_iter):
            X, DX = self.evaluate(q[None], order=1)
            r = X[0] - x
            J = DX[0]
            step = np.linalg.lstsq(J, -r, rcond=None)[0]
            q += step
            if np.linalg.norm(step) < tol * (1 + np.linalg.norm(q)):
                break
        return q, float(np.linalg.norm(self.evaluate(q[None])[0] - x))
