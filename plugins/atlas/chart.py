"""One chart of the atlas: embedded control points, LME parametrization, quadrature points.

For a patch κ (thesis §3.3–3.4, Paper 2 §3.2–3.3): the control points J_κ (points in the
support of ψ_κ plus a margin) are embedded in R^d, Ξ_κ = R_κ(P_κ); the chart is
φ_κ(ξ) = Σ_a p_a(ξ) P_a with local max-ent p_a on Ξ_κ (thesis Eq. 2). Integrals use Gauss
points on a Delaunay triangulation of Ξ_κ,

    ∫_M ψ_κ f dM ≈ Σ_g w_g J_κ(ξ_g) ψ_κ(φ_κ(ξ_g)) f(φ_κ(ξ_g)),   J_κ = sqrt(det Dφᵀ Dφ),

keeping only the points where ψ_κ ∘ φ_κ > tol_pu and where the LME chart exists (inside
the convex hull of Ξ_κ). Optionally the control points are refitted so that the chart passes
through the samples (Paper 2 App. B, here per chart: φ_κ(ξ_a) = x_a for a ∈ J_κ).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.sparse.linalg import splu
from scipy.spatial import Delaunay

from . import differential_geometry as dg
from .quadrature import map_rule_to_simplices, simplex_rule


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


@dataclass
class Chart:
    """A local parametrization φ_κ: conv Ξ_κ ⊂ R^d → R^D."""

    node_index: np.ndarray       # (n,) global indices J_κ of the control points
    xi_nodes: np.ndarray         # (n, d) embedded control points Ξ_κ
    control_points: np.ndarray   # (n, D) P_a (refitted if least squares was used)
    approximant: object          # fitted LME on Ξ_κ
    fit_residual: float          # max |φ_κ(ξ_a) − x_a| over nodes where φ_κ exists

    def evaluate(self, xi: np.ndarray, order: int = 2):
        """(φ, Dφ, D²φ, outside) at parametric points; rows where ``outside`` are zero."""
        basis = self.approximant.evaluate(xi, order=order)
        X, T, S = dg.chart_derivatives(basis, self.control_points, order)
        outside = basis.outside if basis.outside is not None else np.zeros(len(xi), bool)
        return X, T, S, outside

    def geometry(self, xi: np.ndarray) -> dict[str, np.ndarray]:
        """Point, tangents, metric, J, normal, b, H, K at parametric points inside the hull."""
        X, T, S, outside = self.evaluate(xi, order=2)
        out = dg.surface_geometry(T, S)
        out.update(position=X, tangents=T, second_derivatives=S, outside=outside)
        return out


def build_chart(points: np.ndarray, node_index: np.ndarray, embedder, make_approximant:
                Callable[[], object], least_squares_fit: bool) -> Chart:
    """Embed the control points J_κ and build the LME chart on them."""
    P = points[node_index]
    xi = np.asarray(embedder.fit_transform(P), dtype=np.float64)
    lme = make_approximant().fit(xi)
    C = P
    if least_squares_fit:
        C = interpolating_control_points(lme, xi, P)
    basis = lme.evaluate(xi, order=0)
    X, _, _ = dg.chart_derivatives(basis, C, 0)
    ok = np.ones(len(P), bool) if basis.outside is None else ~basis.outside
    resid = float(np.max(np.linalg.norm(X - P, axis=1)[ok], initial=0.0))
    return Chart(node_index, xi, C, lme, resid)


def interpolating_control_points(lme, xi: np.ndarray, samples: np.ndarray) -> np.ndarray:
    """Control points C with Σ_b p_b(ξ_a) C_b = x_a at every node (Paper 2 App. B, per chart).

    The normal equations MᵀM C = Mᵀ X of App. B with as many samples as control points
    reduce to M C = X, M_ab = p_b(ξ_a) (sparse, diagonally dominant for γ ≳ 0.5).
    """
    from scipy.sparse import identity

    n = xi.shape[0]
    basis = lme.evaluate(xi, order=0)
    M = basis.to_csr(n)
    if basis.outside is not None and basis.outside.any():
        # nodes where the LME dual fails (on the hull boundary, where p_a → δ_ab): keep C_a = x_a
        fix = identity(n, format="csr").multiply(basis.outside[:, None].astype(float))
        M = M + fix
    return splu(M.tocsc()).solve(samples)


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
    n_candidates = len(wg)
    basis = chart.approximant.evaluate(xg, order=2 if need_second else 1)
    X, T, S = dg.chart_derivatives(basis, chart.control_points, 2 if need_second else 1)
    outside = basis.outside if basis.outside is not None else np.zeros(len(xg), bool)
    lost = 0.0
    if outside.any():  # diagnostic: ψ_κ at the control point nearest to each dropped point
        from scipy.spatial import cKDTree

        _, j = cKDTree(xi).query(xg[outside], k=1)
        lost = float(np.max(patch_pu(chart.control_points[j]), initial=0.0))
    inside = ~outside
    xg, wg, X, T = xg[inside], wg[inside], X[inside], T[inside]
    S = None if S is None else S[inside]
    psi = patch_pu(X)
    J = dg.area_element(T)
    use = psi > tol_pu
    kept = None
    if keep_basis:
        kept = basis.take(np.flatnonzero(inside)[use]).renumbered(chart.node_index)
    return ChartQuadrature(
        xi=xg[use], weights=(wg * J * psi)[use], positions=X[use], tangents=T[use],
        second=None if S is None else S[use], pu=psi[use], area_element=J[use],
        n_candidates=n_candidates, lost_pu=lost, basis=kept)
