"""The slow manifold x = X(q) learnt from snapshots (thesis §5.2, Appendix B; Millán & Arroyo,
CMAME 261–262 (2013) 118, §3).

Snapshots x_i ∈ R^D with embedding coordinates q_i ∈ R^d (any embedder). The embedding is
binned on a grid of square cells, ``n_bins`` along the longest side; the mean q of the
snapshots in each non-empty cell is a node q_a, and the vertices of the embedding's convex hull
are nodes too (the bin means alone would leave the outermost snapshots outside the basis' domain).
Snapshots the basis still cannot reach (on the hull's boundary, where the LME dual has no
solution) are left out of the fit and counted (``n_unfitted_``). Local max-ent basis
functions p_a(q) on the nodes (the ``approximant`` plugin) parametrise the manifold,
X(q) = Σ_a p_a(q) P_a, with the nodal configurations P_a the least-squares fit to the snapshots,

    min_P Σ_i |Σ_a p_a(q_i) P_a − x_i|²  (+ a ridge of 1e-10 × mean diagonal),

so DX(q) = Σ ∇p_a ⊗ P_a and D²X(q) = Σ ∇∇p_a ⊗ P_a follow from the basis derivatives. The
projection q(x) of a configuration is the closest point, min_q |X(q) − x|², by Gauss–Newton
with a line search from the embedding coordinate of the nearest snapshot (Appendix B). X(q)
is defined only inside the nodes' convex hull: evaluating it outside raises
:class:`OutsideRegion`.
"""
from __future__ import annotations

import numpy as np

from pointatlas.errors import InputError, PointatlasError


class OutsideRegion(PointatlasError):
    """X(q) was asked for at a q outside the sampled region (the LME nodes' convex hull),
    where the slow manifold is not defined."""


def hull_vertices(Q: np.ndarray) -> np.ndarray:
    """The points of Q at the vertices of its convex hull (the two ends for d = 1)."""
    if Q.shape[1] == 1:
        return Q[[np.argmin(Q[:, 0]), np.argmax(Q[:, 0])]]
    from scipy.spatial import ConvexHull

    return Q[ConvexHull(Q).vertices]


def binned_nodes(Q: np.ndarray, n_bins: int) -> np.ndarray:
    """Mean of the points of each non-empty cell of a grid of square (cubic) cells over the
    box of Q, ``n_bins`` cells along its longest side (so the nodes are spaced alike in every
    direction, as the LME locality β = γ/h² assumes)."""
    Q = np.asarray(Q, dtype=np.float64)
    lo, hi = Q.min(axis=0), Q.max(axis=0)
    h = max(float(np.max(hi - lo)), 1e-300) / n_bins
    shape = tuple(int(k) for k in np.maximum(np.ceil((hi - lo) / h), 1))
    cell = np.minimum(((Q - lo) / h).astype(int), np.array(shape) - 1)
    key = np.ravel_multi_index(cell.T, shape)
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
        # a hull vertex alone in its cell is its own bin mean: keep each node once
        self.nodes_ = np.unique(np.concatenate([binned_nodes(Q, self.n_bins),
                                                hull_vertices(Q)]), axis=0)
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
        self.X_, self.Q_, self._sq_ = X, Q, None
        self.residual_ = float(np.sqrt(np.mean(np.sum((B @ self.P_ - X) ** 2, axis=1))))
        return self

    @property
    def dim(self) -> int:
        return self.nodes_.shape[1]

    def evaluate(self, q, order: int = 0):
        """(X (m, D), DX (m, D, d) if order ≥ 1, D²X (m, D, d, d) if order ≥ 2) at q (m, d)."""
        q = np.atleast_2d(np.asarray(q, dtype=np.float64))
        b = self.basis_.evaluate(q, order=order)
        if b.outside is not None and np.any(b.outside):
            i = int(np.flatnonzero(b.outside)[0])
            raise OutsideRegion(f"q = {np.round(q[i], 6).tolist()} lies outside the slow "
                                f"manifold's sampled region (the convex hull of its "
                                f"{len(self.nodes_)} LME nodes)")
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

    def contains(self, q) -> bool:
        """Whether X is defined at q (d,): inside the LME nodes' convex hull."""
        b = self.basis_.evaluate(np.atleast_2d(np.asarray(q, dtype=np.float64)), order=0)
        return b.outside is None or not bool(np.any(b.outside))

    def nearest(self, x) -> int:
        """Index of the training snapshot nearest to x (one matrix-vector product)."""
        if getattr(self, "_sq_", None) is None:
            self._sq_ = np.einsum("ij,ij->i", self.X_, self.X_)
        return int(np.argmin(self._sq_ - 2.0 * (self.X_ @ x)))

    def project(self, x, tol: float = 1e-6, max_iter: int = 20):
        """(q, distance): the closest point of the manifold to x (D,) (Appendix B): Gauss–Newton
        from the nearest snapshot's q with a backtracking line search (a step is halved until
        it stays in the sampled region and lowers |X(q) − x|); stops when the step is below
        ``tol`` relative to 1 + |q| or no step lowers the distance."""
        x = np.asarray(x, dtype=np.float64)
        q = self.Q_[self.nearest(x)].copy()
        X, DX = self.evaluate(q[None], order=1)
        r = float(np.linalg.norm(X[0] - x))
        for _ in range(max_iter):
            step = np.linalg.lstsq(DX[0], x - X[0], rcond=None)[0]
            for _ in range(10):
                if self.contains(q + step):
                    Xn = self.evaluate((q + step)[None])[0]
                    rn = float(np.linalg.norm(Xn - x))
                    if rn <= r:
                        break
                step *= 0.5
            else:
                break
            q, r = q + step, rn
            if np.linalg.norm(step) < tol * (1 + np.linalg.norm(q)):
                break
            X, DX = self.evaluate(q[None], order=1)
        return q, r
