"""Local max-ent (LME) approximants, nodal locality β_a = γ/h_a² (thesis Box 2, Paper 1 §2.4).

p_a(x) = exp(-β_a|x - x_a|² + λ*·(x - x_a)) / Z(x, λ*),  λ* = argmin_λ log Z(x, λ):
non-negative, partition of unity, linear reproduction (Σ p_a x_a = x), C^∞, defined only
inside the convex hull of the nodes. Kernels and derivative formulas: :mod:`.lme_kernels`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numba
import numpy as np
from scipy.spatial import cKDTree

from pointatlas.basis import BasisFunctions
from pointatlas.constraints import Options, validate_parameters
from pointatlas.errors import InputError
from pointatlas.stores_config import stores_config

from . import lme_kernels as K
from .lme_kernel_2d import lme_kernel_2d
from .support import RebuildsCellLists, SupportGrid, locality, nodal_spacing, support_radius, threads_for
from .validation import (
    NEWTON_CONSTRAINTS,
    NewtonLocalityConfig,
    check_nodes,
    check_order,
    check_points,
    compact_rows,
    replace_rows,
    spacing_neighbors,
)

#: polynomial degree of each ``reproduction`` other than 'linear'
POLYNOMIAL_DEGREE = {"quadratic": 2, "cubic": 3, "quartic": 4}


@stores_config
class LocalMaxEnt(RebuildsCellLists):
    """Local max-ent basis functions on scattered nodes in any dimension d.

    Parameters
    ----------
    gamma : aspect ratio γ = β_a h_a² (larger: sharper, more local; → ∞ gives Delaunay hats).
    tol : support cut-off; node a is ignored where exp(-β_a|x - x_a|²) < tol.
    n_spacing_neighbors : h_a is the mean distance from node a to this many nearest nodes;
        None (default) means 2·d, which gives h_a = h exactly on a Cartesian grid of spacing h.
    newton_tol : Newton on λ stops when |r| = |Σ p_a (x - x_a)| < newton_tol · h_ref,
        h_ref = median h_a (so the test is independent of the length unit).
    max_iter : Newton iterations before a point is declared outside the hull.
    outside : 'error' raises InputError on points outside the convex hull of the nodes;
        'flag' marks them in ``BasisFunctions.outside`` and leaves their rows empty.
    hessians : 'exact' (∂²p_a, Paper 1 App. A) or 'consistent' (the Hessian of the
        LME-weighted quadratic least-squares fit, exact for quadratics on any nodes; see
        :mod:`.weighted_polynomial_fit`). Use 'consistent' for curvatures on irregular nodes.
    reproduction : 'linear' (the LME basis) or 'quadratic', 'cubic', 'quartic': values,
        gradients and Hessians of the weighted polynomial least-squares fit of that degree
        instead (moving least squares on the LME support with LME's Gaussian prior
        exp(-β_a|x - x_a|²) as weights,
        :func:`.weighted_polynomial_fit.polynomial_fit_basis`), which reproduce polynomials
        of that degree exactly on any nodes. For geometry on irregular points (an atlas
        chart through samples: 'quartic' gives curvatures to ~1e-4 where LME's are O(1) off),
        not as Galerkin shape functions: the values may be negative and the derivatives are
        diffuse, not the derivatives of the values. Overrides ``hessians``.

    The support nodes of x are those with |x - x_a| < r_a = sqrt(-ln(tol)/β_a). Where the
    dual cannot be solved on them (strongly varying h_a: x in a gap between clusters), x is
    solved again on every node within max r_a, then twice that, ... (see ``_retry``);
    only then is it declared outside the hull.
    """

    @dataclass
    class Config(NewtonLocalityConfig):
        gamma: float = 0.8
        tol: float = 1e-10
        hessians: str = "exact"
        reproduction: str = "linear"

        parameter_constraints: ClassVar[dict[str, list]] = {
            **NEWTON_CONSTRAINTS,
            "hessians": [Options(("exact", "consistent"))],
            "reproduction": [Options(("linear", *POLYNOMIAL_DEGREE))],
        }

    _cell_list_attributes = ("grid_", "entry_beta_")
    description: ClassVar[str] = "Local max-ent basis functions (nodal locality β_a = γ/h_a²)."

    def fit(self, nodes) -> "LocalMaxEnt":
        """Store the (n, d) nodes; compute h_a, β_a = γ/h_a², cut-off radii and cell lists."""
        validate_parameters(self)
        X = check_nodes(nodes, plugin="LocalMaxEnt")
        n, d = X.shape
        k = spacing_neighbors(self.n_spacing_neighbors, d, n, plugin="LocalMaxEnt")
        self.tree_ = cKDTree(X)
        self.nodes_ = X
        self.spacing_ = nodal_spacing(self.tree_, X, k)
        self.beta_ = locality(self.spacing_, float(self.gamma))
        self.radius_ = support_radius(self.beta_, float(self.tol))
        self.h_ref_ = float(np.median(self.spacing_))
        self._build_grid()
        return self

    def _build_grid(self) -> None:
        """The cell lists of the supports and β of every entry, contiguous for the kernel
        (None on the kd-tree path)."""
        self.grid_ = SupportGrid(self.nodes_, self.radius_)
        entries = getattr(self.grid_, "entries", None)
        self.entry_beta_ = None if entries is None else self.beta_[entries]

    @property
    def n_nodes(self) -> int:
        return self.nodes_.shape[0]

    def evaluate(self, points, order: int = 0) -> BasisFunctions:
        """p_a at the (m, d) points, with gradients (order ≥ 1) and Hessians (order 2)."""
        x, basis, status = self._evaluate_flagged(points, order)
        bad = basis.outside
        if bad is not None and self.outside == "error":
            i = int(np.flatnonzero(bad)[0])
            raise InputError(self._outside_message(i, x[i], int(bad.sum()), status[i]))
        return basis

    def _evaluate_flagged(self, points, order: int):
        """(x, basis with the points outside the domain flagged (never raised), status)."""
        if not hasattr(self, "nodes_"):
            raise InputError(f"{type(self).__name__}.evaluate called before fit; call "
                             "fit(nodes) first.")
        validate_parameters(self)
        order = check_order(order, 2, plugin=type(self).__name__)
        d = self.nodes_.shape[1]
        x = check_points(points, d, plugin=type(self).__name__)
        indptr, arrays, status = self._solve(self.grid_.cells(x), order)
        bad = status != K.OK
        if bad.any():
            indptr, arrays, status = self._retry(x, order, indptr, arrays, status)
            bad = status != K.OK
        indices, values, grads, hess = arrays
        fit = self.reproduction != "linear"
        if fit or (order == 2 and self.hessians == "consistent"):
            grads, hess = self._second_order(x, bad, indptr, indices, values, grads, hess,
                                             order, fit)
        if not bad.any():
            return x, BasisFunctions(indptr, indices, values, grads, hess, None), status
        indptr, (indices, values, grads, hess) = compact_rows(
            indptr, ~bad, indices, values, grads, hess)
        return x, BasisFunctions(indptr, indices, values, grads, hess, bad), status

    def _second_order(self, x, bad, indptr, indices, values, grads, hess, order, fit):
        """Replace, in place on the rows of the points where LME exists, the Hessians
        (hessians='consistent') or values, gradients and Hessians (reproduction other than
        'linear') by those of the weighted polynomial fit (:mod:`.weighted_polynomial_fit`)."""
        from . import weighted_polynomial_fit as wpf
        from .weighted_polynomial_fit import consistent_hessians, polynomial_fit_basis

        d = self.nodes_.shape[1]
        nnz = len(values)
        g = grads if order >= 1 else np.empty((nnz, d))
        H = hess if order >= 2 else np.empty((nnz, d, d))
        if bad.any():
            keep = np.repeat(~bad, np.diff(indptr))
            rows = np.concatenate([[0], np.cumsum(np.diff(indptr)[~bad])]).astype(indptr.dtype)
            args = (rows, indices[keep], x[~bad])
            sub = [np.ascontiguousarray(a[keep]) for a in (values, g, H)]
        else:
            args = (indptr, indices, x)
            sub = [values, g, H]
        if fit:
            # the weights: LME's prior exp(-β_a |x - x_a|²) on its support, not p_a, whose
            # tilt (λ) concentrates them on a few nodes at the rim of a gap in the samples,
            # where the fit would then be ill-posed (measured on 20 000 random sphere points:
            # Willmore error 6.3e-3 with p_a, 3.3e-4 with the prior)
            row = np.repeat(np.arange(len(args[0]) - 1), np.diff(args[0]))
            w = np.exp(-self.beta_[args[1]] * np.sum((self.nodes_[args[1]] - args[2][row]) ** 2,
                                                     axis=1))
            polynomial_fit_basis(args[0], args[1], sub[0], sub[1], self.nodes_, args[2],
                                 self.h_ref_, 1e6, POLYNOMIAL_DEGREE[self.reproduction], sub[2],
                                 w, wpf.MAX_LEBESGUE)
        else:
            consistent_hessians(args[0], args[1], sub[0], self.nodes_, args[2], self.h_ref_,
                                1e6, sub[2])
        if bad.any():
            values[keep], g[keep], H[keep] = sub
        return (grads if order >= 1 else None), (hess if order >= 2 else None)

    def _retry(self, x, order, indptr, arrays, status):
        """Solve failed points again with every node within R = max r_a, 2R, 4R, ...

        With strongly varying h_a (clusters and gaps) the nodes whose own cut-off reaches x
        may not surround it although x is inside the hull of all nodes. Points outside the
        nodes' bounding box are outside the hull and are not retried; the radius grows until
        it spans the bounding box (then every node takes part and failure is definitive).
        """
        lo, hi = self.nodes_.min(axis=0), self.nodes_.max(axis=0)
        diag = float(np.linalg.norm(hi - lo))
        in_box = np.all((x >= lo) & (x <= hi), axis=1)
        radius = float(self.radius_.max())
        while True:
            rows = np.flatnonzero((status != K.OK) & in_box)
            if len(rows) == 0:
                break
            sub_indptr, sub_arrays, sub_status = self._solve(
                self.grid_.cells_within(x[rows], radius), order)
            indptr, arrays = replace_rows(indptr, arrays, rows, sub_indptr, sub_arrays)
            status[rows] = sub_status
            if radius > diag:
                break
            radius *= 2.0
        return indptr, arrays, status

    def _solve(self, cells, order):
        """Run the kernel on ``cells``: (indptr, [indices, values, grads, hess], status)."""
        d = self.nodes_.shape[1]
        indptr = cells.count()
        nnz = int(indptr[-1])
        indices = np.empty(nnz, dtype=np.int64)
        values = np.empty(nnz)
        grads = np.empty((nnz if order >= 1 else 0, d))
        hess = np.empty((nnz if order >= 2 else 0, d, d))
        status = np.empty(len(cells.points), dtype=np.int64)
        entry_beta = (self.entry_beta_ if cells.entries is getattr(self.grid_, "entries", None)
                      else self.beta_[cells.entries])
        # dynamic scheduling (chunks of 4 × 64 points): the per-point cost varies and the
        # cores may be shared, so a static split would leave a thread waiting
        previous = numba.set_parallel_chunksize(4)
        try:
            kernel = lme_kernel_2d if d == 2 else K.lme_kernel
            with threads_for(len(cells.points)):
                kernel(*cells.args(), entry_beta, indptr,
                       float(self.newton_tol) * self.h_ref_, int(self.max_iter), order,
                       indices, values, grads, hess, status)
        finally:
            numba.set_parallel_chunksize(previous)
        arrays = [indices, values, grads if order >= 1 else None, hess if order >= 2 else None]
        return indptr, arrays, status

    @staticmethod
    def _outside_message(i, xi, n_bad, code) -> str:
        why = {K.NO_SUPPORT: "no d+1 nodes have their support there",
               K.SINGULAR: "J(λ*) is numerically singular, so derivatives are undefined"}.get(
                   int(code), "the dual problem min_λ log Z has no minimiser")
        return (
            f"LocalMaxEnt: evaluation point {i} at {np.array2string(xi, precision=6)} "
            f"({n_bad} point(s) in all) lies outside the convex hull of the nodes, where LME "
            f"basis functions do not exist ({why}), or so close to its boundary (within a "
            "fraction of the node spacing, where the hull is spanned by distant nodes) that the "
            "dual cannot be solved. Evaluate only inside the hull (test with "
            "scipy.spatial.Delaunay(nodes).find_simplex(points) >= 0), add nodes around the "
            "region, or pass outside='flag' to mark such points instead of raising."
        )
