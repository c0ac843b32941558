"""One chart of the atlas: embedded control points, LME parametrization, quadrature points.

For a patch κ (thesis §3.3–3.4, Paper 2 §3.2–3.3): the control points J_κ (points in the
support of ψ_κ plus a margin) are embedded in R^d, Ξ_κ = R_κ(P_κ); the chart is
φ_κ(ξ) = Σ_a p_a(ξ) P_a with local max-ent p_a on Ξ_κ (thesis Eq. 2). Integrals use Gauss
points on a Delaunay triangulation of Ξ_κ,

    ∫_M ψ_κ f dM ≈ Σ_g w_g J_κ(ξ_g) ψ_κ(φ_κ(ξ_g)) f(φ_κ(ξ_g)),   J_κ = sqrt(det Dφᵀ Dφ),

keeping only the points where ψ_κ ∘ φ_κ > tol_pu and where the LME chart exists (inside
the convex hull of Ξ_κ) — Delaunay simplices of Ξ_κ for d ≥ 2 (triangles, tetrahedra), the
intervals between consecutive sorted nodes for d = 1. Optionally the control points are
refitted so that the chart passes through the samples (Paper 2 App. B, here per chart:
φ_κ(ξ_a) = x_a for a ∈ J_κ; the global fit of App. B is in :mod:`.surface_fit`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numba as nb
import numpy as np
from scipy.sparse import identity
from scipy.sparse.linalg import splu
from scipy.spatial import Delaunay

from . import differential_geometry as dg
from .chart_fidelity import chart_departure
from .quadrature import map_rule_to_simplices, simplex_rule


@nb.njit(parallel=True, cache=True)
def _combine_kernel(indptr, indices, values, grads, hess, C, order, X, T, S):
    """X_i = Σ_q p_q C_{a_q}, T_iα = Σ_q ∂_α p_q C_{a_q}, S_iαβ = Σ_q ∂_αβ p_q C_{a_q} (CSR rows).

    Sums run over each row in storage order, as scipy's CSR product does.
    """
    m = indptr.shape[0] - 1
    D = C.shape[1]
    d = grads.shape[1]
    for i in nb.prange(m):
        for q in range(indptr[i], indptr[i + 1]):
            a = indices[q]
            v = values[q]
            for c in range(D):
                cc = C[a, c]
                X[i, c] += v * cc
                if order >= 1:
                    for k in range(d):
                        T[i, k, c] += grads[q, k] * cc
                if order >= 2:
                    for k in range(d):
                        for j in range(k, d):
                            S[i, k, j, c] += hess[q, k, j] * cc
        if order >= 2:
            for k in range(d):
                for j in range(k + 1, d):
                    for c in range(D):
                        S[i, j, k, c] = S[i, k, j, c]


@nb.njit(parallel=True, cache=True)
def _combine_surface_kernel(indptr, indices, values, grads, hess, C, X, T, S):
    """:func:`_combine_kernel` for d = 2, D = 3, order 2 with the sums held in registers."""
    m = indptr.shape[0] - 1
    for i in nb.prange(m):
        x0 = x1 = x2 = 0.0
        t00 = t01 = t02 = t10 = t11 = t12 = 0.0
        s000 = s001 = s002 = s010 = s011 = s012 = s110 = s111 = s112 = 0.0
        for q in range(indptr[i], indptr[i + 1]):
            a = indices[q]
            v, g0, g1 = values[q], grads[q, 0], grads[q, 1]
            h00, h01, h11 = hess[q, 0, 0], hess[q, 0, 1], hess[q, 1, 1]
            c0, c1, c2 = C[a, 0], C[a, 1], C[a, 2]
            x0 += v * c0
            x1 += v * c1
            x2 += v * c2
            t00 += g0 * c0
            t01 += g0 * c1
            t02 += g0 * c2
            t10 += g1 * c0
            t11 += g1 * c1
            t12 += g1 * c2
            s000 += h00 * c0
            s001 += h00 * c1
            s002 += h00 * c2
            s010 += h01 * c0
            s011 += h01 * c1
            s012 += h01 * c2
            s110 += h11 * c0
            s111 += h11 * c1
            s112 += h11 * c2
        X[i, 0], X[i, 1], X[i, 2] = x0, x1, x2
        T[i, 0, 0], T[i, 0, 1], T[i, 0, 2] = t00, t01, t02
        T[i, 1, 0], T[i, 1, 1], T[i, 1, 2] = t10, t11, t12
        S[i, 0, 0, 0], S[i, 0, 0, 1], S[i, 0, 0, 2] = s000, s001, s002
        S[i, 0, 1, 0], S[i, 0, 1, 1], S[i, 0, 1, 2] = s010, s011, s012
        S[i, 1, 0, 0], S[i, 1, 0, 1], S[i, 1, 0, 2] = s010, s011, s012
        S[i, 1, 1, 0], S[i, 1, 1, 1], S[i, 1, 1, 2] = s110, s111, s112


#: below this many points the kernels run on one thread (a parallel region costs more)
PARALLEL_MIN_POINTS = 4000


def chart_derivatives(basis, control_points: np.ndarray, order: int = 2):
    """φ = Σ_a p_a P_a, Dφ and D²φ (thesis Eq. 2) in one pass over the sparse basis.

    Same result as :func:`differential_geometry.chart_derivatives` (X (m, D), T (m, d, D) or
    None, S (m, d, d, D) or None) without building one scipy matrix per derivative.
    """
    C = np.ascontiguousarray(control_points, dtype=np.float64)
    m, D = basis.n_points, C.shape[1]
    d = basis.gradients.shape[1] if order >= 1 else 0
    X = np.zeros((m, D))
    T = np.zeros((m, d, D)) if order >= 1 else None
    S = np.zeros((m, d, d, D)) if order >= 2 else None
    args = (np.asarray(basis.indptr, np.int64), np.asarray(basis.indices, np.int64),
            np.ascontiguousarray(basis.values, np.float64))
    threads = nb.get_num_threads()
    if m < PARALLEL_MIN_POINTS:
        nb.set_num_threads(1)
    try:
        if order == 2 and d == 2 and D == 3:
            _combine_surface_kernel(*args, np.ascontiguousarray(basis.gradients),
                                    np.ascontiguousarray(basis.hessians), C, X, T, S)
        else:
            _combine_kernel(
                *args,
                np.ascontiguousarray(basis.gradients) if order >= 1 else np.zeros((0, 1)),
                np.ascontiguousarray(basis.hessians) if order >= 2 else np.zeros((0, 1, 1)),
                C, int(order), X, T if T is not None else np.zeros((0, 1, D)),
                S if S is not None else np.zeros((0, 1, 1, D)))
    finally:
        nb.set_num_threads(threads)
    return X, T, S


@dataclass
class ChartQuadrature:
    """Quadrature data of one chart: weights include J and ψ_κ (sum of weights = ∫ψ_κ dM)."""

    xi: np.ndarray            # (m, d) parametric points
    weights: np.ndarray       # (m,) w_g J_κ(ξ_g) ψ_κ(φ_κ(ξ_g))
    positions: np.ndarray     # (m, D) φ_κ(ξ_g)
    tangents: np.ndarray      # (m, d, D) ∂φ_κ/∂ξ_α
    second: np.ndarray | None  # (m, d, d, D) ∂²φ_κ/∂ξ_α∂ξ_β
    pu: np.ndarray            # (m,) ψ_κ(φ_κ(ξ_g))
    area_element: np.ndarray  # (m,) J_κ(ξ_g)
    n_candidates: int         # Gauss points before dropping those with ψ_κ ≈ 0
    lost_pu: float            # largest ψ_κ at a Gauss point dropped because LME is undefined
    basis: object = None      # BasisFunctions at the kept points (global node ids), if asked
    departure: dict = None    # chart_fidelity.chart_departure: where φ_κ leaves its samples


@dataclass
class Chart:
    """A local parametrization φ_κ: conv Ξ_κ ⊂ R^d → R^D."""

    node_index: np.ndarray       # (n,) global indices J_κ of the control points
    xi_nodes: np.ndarray         # (n, d) embedded control points Ξ_κ
    control_points: np.ndarray   # (n, D) P_a (refitted if least squares was used)
    approximant: object          # fitted LME on Ξ_κ
    fit_residual: float          # max |φ_κ(ξ_a) − x_a| over nodes where φ_κ exists
    samples: np.ndarray | None = None  # (n, D) the points x_a (None: the control points)

    def evaluate(self, xi: np.ndarray, order: int = 2):
        """(φ, Dφ, D²φ, outside) at parametric points; rows where ``outside`` are zero."""
        basis = self.approximant.evaluate(xi, order=order)
        X, T, S = chart_derivatives(basis, self.control_points, order)
        outside = basis.outside if basis.outside is not None else np.zeros(len(xi), bool)
        return X, T, S, outside

    def geometry(self, xi: np.ndarray) -> dict[str, np.ndarray]:
        """Point, tangents, second derivatives and the :class:`differential_geometry.Geometry`
        (metric, J; normal, b, H, K for a surface in R^3; the rest on access)."""
        X, T, S, outside = self.evaluate(xi, order=2)
        out = dg.surface_geometry(T, S)
        out.update(position=X, tangents=T, second_derivatives=S, outside=outside)
        return out


def build_chart(points: np.ndarray, node_index: np.ndarray, embedder, make_approximant:
                Callable[[], object], least_squares_fit: bool,
                xi: np.ndarray | None = None) -> Chart:
    """Embed the control points J_κ (unless their embedding ``xi`` is given) and build the
    LME chart on them; with ``least_squares_fit`` its control points are fitted so that it
    interpolates the points (Paper 2 App. B)."""
    P = points[node_index]
    if xi is None:
        xi = embedder.fit_transform(P)
    xi = np.asarray(xi, dtype=np.float64)
    lme = make_approximant().fit(xi)
    basis = lme.evaluate(xi, order=0)
    C = P
    if least_squares_fit:
        C = interpolating_control_points(lme, xi, P, basis)
    X, _, _ = chart_derivatives(basis, C, 0)
    ok = np.ones(len(P), bool) if basis.outside is None else ~basis.outside
    resid = float(np.max(np.linalg.norm(X - P, axis=1)[ok], initial=0.0))
    return Chart(node_index, xi, C, lme, resid, samples=P)


#: charts with at most this many control points solve the interpolation system densely
DENSE_SOLVE_MAX = 2000


def one_blas_thread():
    """Context limiting every BLAS library loaded at entry to one thread.

    The libraries are scanned at each entry (1.7 ms): one loaded after a cached scan (MKL,
    when PARDISO is first used) was left multithreaded. The limit is process-wide: enter it
    in the thread that starts worker threads, not in each worker (a worker's exit restored
    multithreaded BLAS under the others mid-way and left BLAS at one thread after them; the
    tangent then differed from call to call at round-off)."""
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController().limit(limits=1, user_api="blas")


def interpolating_control_points(lme, xi: np.ndarray, samples: np.ndarray,
                                 basis=None) -> np.ndarray:
    """Control points C with Σ_b p_b(ξ_a) C_b = x_a at every node (Paper 2 App. B, per chart).

    The normal equations MᵀM C = Mᵀ X of App. B with as many samples as control points
    reduce to M C = X, M_ab = p_b(ξ_a) (sparse, diagonally dominant for γ ≳ 0.5).
    ``basis``: the LME basis at the nodes ξ, if already evaluated.
    """
    n = xi.shape[0]
    if basis is None:
        basis = lme.evaluate(xi, order=0)
    M = basis.to_csr(n)
    if basis.outside is not None and basis.outside.any():
        # nodes where the LME dual fails (on the hull boundary, where p_a → δ_ab): keep C_a = x_a
        fix = identity(n, format="csr").multiply(basis.outside[:, None].astype(float))
        M = M + fix
    if n <= DENSE_SOLVE_MAX:
        # a few hundred nodes with ~80 non-zeros a row: one-thread LAPACK LU is ~7x faster
        # than SuperLU (and threaded BLAS only fights the numba threads at this size)
        with one_blas_thread():
            return np.linalg.solve(M.toarray(), samples)
    return splu(M.tocsc()).solve(samples)


def area_element(T: np.ndarray) -> np.ndarray:
    """J = sqrt(det a), a_αβ = φ_α·φ_β (thesis §3.4); explicit 2×2 determinant for d = 2."""
    if T.shape[1] != 2:
        return dg.area_element(T)
    a00 = np.einsum("mi,mi->m", T[:, 0], T[:, 0])
    a11 = np.einsum("mi,mi->m", T[:, 1], T[:, 1])
    a01 = np.einsum("mi,mi->m", T[:, 0], T[:, 1])
    return np.sqrt(np.clip(a00 * a11 - a01 * a01, 0.0, None))


def chart_quadrature(chart: Chart, support_at_nodes: np.ndarray, patch_pu: Callable,
                     order: int, tol_pu: float, need_second: bool = True,
                     real: np.ndarray | None = None, keep_basis: bool = False
                     ) -> ChartQuadrature:
    """Gauss points on the Delaunay triangles of Ξ_κ that meet the support of ψ_κ.

    support_at_nodes : ψ_κ at the control points (a triangle is used if one of its vertices
        has ψ_κ > tol_pu·1e-3); patch_pu(X) returns ψ_κ at ambient points X (m, D).
    real : optional (n,) bool over the chart's control points; triangles with a vertex that
        is not real (a ghost node beyond the boundary, Paper 1 §4.1.2) are not integrated,
        so the integrals cover the sampled surface only.
    keep_basis : keep the basis functions at the kept points (global node ids) for assembly.
    """
    xi = chart.xi_nodes
    d = xi.shape[1]
    if d == 1:
        o = np.argsort(xi[:, 0])
        simplices = np.column_stack([o[:-1], o[1:]])
    else:
        simplices = Delaunay(xi).simplices
    keep = support_at_nodes[simplices].max(axis=1) > tol_pu * 1e-3
    if real is not None:
        keep &= np.asarray(real, bool)[simplices].all(axis=1)
    simplices = simplices[keep]
    rule = simplex_rule(d, order)
    xg, wg = map_rule_to_simplices(xi[simplices], rule)
    tri = np.repeat(np.arange(len(simplices)), rule.n_points)   # simplex-major points
    n_candidates = len(wg)
    basis = chart.approximant.evaluate(xg, order=2 if need_second else 1)
    X, T, S = chart_derivatives(basis, chart.control_points, 2 if need_second else 1)
    outside = basis.outside if basis.outside is not None else np.zeros(len(xg), bool)
    lost = 0.0
    if outside.any():  # diagnostic: ψ_κ at the control point nearest to each dropped point
        from scipy.spatial import cKDTree

        _, j = cKDTree(xi).query(xg[outside], k=1)
        lost = float(np.max(patch_pu(chart.control_points[j]), initial=0.0))
    inside = ~outside
    if outside.any():
        xg, wg, X, T, tri = xg[inside], wg[inside], X[inside], T[inside], tri[inside]
        S = None if S is None else S[inside]
    psi = patch_pu(X)
    J = area_element(T)
    use = psi > tol_pu
    kept = None
    if keep_basis:
        # the candidates' basis is not used below: its arrays are compacted in place
        kept = basis.compacted(np.flatnonzero(inside)[use]).renumbered(chart.node_index)
    samples = chart.control_points if chart.samples is None else chart.samples
    departure = chart_departure(xi, samples, simplices[tri[use]], T[use], (wg * J * psi)[use])
    return ChartQuadrature(
        xi=xg[use], weights=(wg * J * psi)[use], positions=X[use], tangents=T[use],
        second=None if S is None else S[use], pu=psi[use], area_element=J[use],
        n_candidates=n_candidates, lost_pu=lost, basis=kept, departure=departure)
