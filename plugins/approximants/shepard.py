"""Gaussian Shepard partition of unity (thesis §3.2, "Shepard partition of unity").

    w_a(x) = exp(-β_a |x - x_a|²)  (dropped where w_a < tol),   ψ_a(x) = w_a(x) / Σ_b w_b(x),

with nodal β_a = γ/h_a² as for the LME approximants. With y_a = x - x_a,
m = 2 Σ_b ψ_b β_b y_b and β̄ = Σ_b ψ_b β_b:

    ∇ψ_a = ψ_a g_a,  g_a = m - 2 β_a y_a,
    Hψ_a = ψ_a [ g_a⊗g_a + 2(β̄ - β_a) I + 2 Σ_b β_b ψ_b y_b⊗g_b ].

Works in any ambient dimension D (markers of a d-manifold in R^D).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numba as nb
import numpy as np
from scipy.spatial import cKDTree

from pointatlas.basis import BasisFunctions
from pointatlas.constraints import validate_parameters
from pointatlas.errors import InputError
from pointatlas.stores_config import stores_config

from .support import RebuildsCellLists, SupportGrid, locality, nodal_spacing, scan, support_radius
from .validation import (
    LocalityConfig,
    check_nodes,
    check_order,
    check_points,
    compact_rows,
    spacing_neighbors,
)


@nb.njit(parallel=True, cache=True, fastmath={"contract", "reassoc", "arcp", "nsz"})
def shepard_kernel(points, visit, cell, starts, entries, entry_x, entry_r2, beta, indptr,
                   order, indices, values, grads, hess):
    """ψ_a (and derivatives up to ``order``) at all points in CSR layout (module docstring).

    Arguments as in :func:`lme_kernels.lme_kernel`; rows with no support node stay empty.
    """
    m, d = points.shape
    for ii in nb.prange(m):
        i = visit[ii]
        lo = indptr[i]
        k = indptr[i + 1] - lo
        if k == 0:
            continue
        scan(points[i], cell[i], starts, entries, entry_x, entry_r2, indices, lo, True)
        y = np.empty((k, d))
        bl = np.empty(k)
        z = 0.0
        for q in range(k):
            e = indices[lo + q]
            a = entries[e]
            indices[lo + q] = a
            bl[q] = beta[a]
            d2 = 0.0
            for j in range(d):
                t = points[i, j] - entry_x[j, e]
                y[q, j] = t
                d2 += t * t
            w = np.exp(-bl[q] * d2)
            values[lo + q] = w
            z += w
        bbar = 0.0
        mv = np.zeros(d)
        for q in range(k):
            psi = values[lo + q] / z
            values[lo + q] = psi
            bbar += psi * bl[q]
            for j in range(d):
                mv[j] += 2.0 * psi * bl[q] * y[q, j]
        if order == 0:
            continue
        g = np.empty((k, d))
        for q in range(k):
            for j in range(d):
                g[q, j] = mv[j] - 2.0 * bl[q] * y[q, j]
                grads[lo + q, j] = values[lo + q] * g[q, j]
        if order < 2:
            continue
        Dm = np.zeros((d, d))
        for q in range(k):
            c = 2.0 * bl[q] * values[lo + q]
            for a in range(d):
                for b in range(d):
                    Dm[a, b] += c * y[q, a] * g[q, b]
        for q in range(k):
            diag = 2.0 * (bbar - bl[q])
            for a in range(d):
                for b in range(d):
                    s = g[q, a] * g[q, b] + Dm[a, b]
                    if a == b:
                        s += diag
                    hess[lo + q, a, b] = values[lo + q] * s


@stores_config
class Shepard(RebuildsCellLists):
    """Gaussian Shepard partition of unity on scattered nodes (markers) in any dimension.

    Parameters
    ----------
    gamma : aspect ratio γ = β_a h_a².
    tol : node a is dropped where exp(-β_a|x - x_a|²) < tol (compact support).
    n_spacing_neighbors : h_a = mean distance to this many nearest nodes; None means 2·D.
    outside : 'error' raises InputError on a point no node's support reaches; 'flag' marks it
        in ``BasisFunctions.outside`` and leaves its row empty.
    """

    @dataclass
    class Config(LocalityConfig):
        gamma: float = 4.0
        tol: float = 1e-6

    description: ClassVar[str] = "Gaussian Shepard partition of unity (nodal β_a = γ/h_a²)."

    def fit(self, nodes) -> "Shepard":
        """Store the (n, D) nodes; compute h_a, β_a, cut-off radii and cell lists."""
        validate_parameters(self)
        X = check_nodes(nodes, plugin="Shepard", min_nodes=2)
        n, dim = X.shape
        k = spacing_neighbors(self.n_spacing_neighbors, dim, n, plugin="Shepard")
        self.nodes_ = X
        self.spacing_ = nodal_spacing(cKDTree(X), X, k)
        self.beta_ = locality(self.spacing_, float(self.gamma))
        self.radius_ = support_radius(self.beta_, float(self.tol))
        self._build_grid()
        return self

    def _build_grid(self) -> None:
        """The cell lists of the supports (:class:`~.support.RebuildsCellLists`)."""
        self.grid_ = SupportGrid(self.nodes_, self.radius_)

    def evaluate(self, points, order: int = 0) -> BasisFunctions:
        """ψ_a at the (m, D) points, with gradients (order ≥ 1) and Hessians (order 2)."""
        if not hasattr(self, "nodes_"):
            raise InputError("Shepard.evaluate called before fit; call fit(nodes) first.")
        validate_parameters(self)
        order = check_order(order, 2, plugin="Shepard")
        dim = self.nodes_.shape[1]
        x = check_points(points, dim, plugin="Shepard")
        cells = self.grid_.cells(x)
        indptr = cells.count()
        nnz = int(indptr[-1])
        indices = np.empty(nnz, dtype=np.int64)
        values = np.empty(nnz)
        grads = np.empty((nnz if order >= 1 else 0, dim))
        hess = np.empty((nnz if order >= 2 else 0, dim, dim))
        shepard_kernel(*cells.args(), self.beta_, indptr, order, indices, values, grads, hess)
        grads = grads if order >= 1 else None
        hess = hess if order >= 2 else None
        bad = np.diff(indptr) == 0
        if not bad.any():
            return BasisFunctions(indptr, indices, values, grads, hess, None)
        if self.outside == "error":
            i = int(np.flatnonzero(bad)[0])
            raise InputError(
                f"Shepard: evaluation point {i} at {np.array2string(x[i], precision=6)} "
                f"({int(bad.sum())} point(s) in all) is reached by no node's support "
                f"(weights below tol={self.tol:g} everywhere), so the partition of unity is "
                "undefined there. Evaluate closer to the nodes, lower tol or gamma, or pass "
                "outside='flag' to mark such points instead of raising."
            )
        indptr, (indices, values, grads, hess) = compact_rows(
            indptr, ~bad, indices, values, grads, hess)
        return BasisFunctions(indptr, indices, values, grads, hess, bad)
