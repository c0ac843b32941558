"""Closest-point projection onto an atlas and its blended single representation π(x).

Paper 2 Appendix A (thesis L2557–2579): for a point x ∈ R^D near the manifold and one chart
φ_κ, the pre-image of the closest point is ξ_κ(x) = argmin_ξ f(ξ), f(ξ) = ½|φ_κ(ξ) − x|²,
found by Newton's method ξ ← ξ − H⁻¹ ∇f with

    ∇f_α = φ_α · (φ − x),        H_αβ = φ_α · φ_β + (φ − x) · φ_αβ

(φ_α = ∂φ_κ/∂ξ_α, φ_αβ = ∂²φ_κ/∂ξ_α∂ξ_β). Here the start is the ξ of the chart's control
point nearest to x (the thesis uses LLE-like weights of the k nearest points; both start
inside the basin of quadratic convergence for points within a fraction of the curvature
radius). Steps are damped by backtracking (Armijo) and fall back to the Gauss–Newton matrix
φ_α·φ_β where H is not positive definite; every iterate stays where the LME chart exists
(inside the convex hull of Ξ_κ).

The charts tried for x are N_x = {κ : ψ_κ(x) > 0} (thesis §3.5, L347); the closest-point
projection keeps the chart giving the smallest distance, and the blended representation is
thesis Eq. (3),

    π(x) = Σ_{κ ∈ N_x} ψ_κ(x) φ_κ(ξ_κ(x)),

"almost a projection": a single smooth map onto (a neighbourhood of) the surface.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from scipy.spatial import cKDTree

from pointatlas.errors import InputError

from . import differential_geometry as dg
from .partition import label_groups


@dataclass
class Projection:
    """Closest-point projections of m points onto the atlas (rows: points)."""

    chart: np.ndarray       # (m,) chart κ giving the closest point, -1 if none was found
    xi: np.ndarray          # (m, d) pre-image ξ_κ(x) in that chart
    point: np.ndarray       # (m, D) projected point φ_κ(ξ)
    distance: np.ndarray    # (m,) |x − φ_κ(ξ)|
    normal: Optional[np.ndarray]  # (m, D) unit normal (hypersurfaces, D = d + 1), towards x
    #                               if x is off M; None in higher codimension
    converged: np.ndarray   # (m,) Newton reached a stationary point inside the chart
    n_iter: np.ndarray      # (m,) Newton iterations in the chosen chart


@dataclass
class ChartNewton:
    """Result of :func:`newton_on_chart` for points projected on one chart."""

    xi: np.ndarray          # (m, d)
    point: np.ndarray       # (m, D) φ(ξ)
    tangents: np.ndarray    # (m, d, D) Dφ(ξ)
    distance: np.ndarray    # (m,)
    converged: np.ndarray   # (m,) bool
    n_iter: np.ndarray      # (m,)
    history: list           # per iteration: (m,) |Δξ| of the step taken (NaN once stopped)


def _chart_scale(chart) -> float:
    """Diameter of the chart's parametric box (length unit of ξ for the stopping tests)."""
    xi = chart.xi_nodes
    return float(np.linalg.norm(xi.max(axis=0) - xi.min(axis=0))) or 1.0


def _inside_start(chart, xi0: np.ndarray) -> np.ndarray:
    """Move starting points that the LME chart flags (hull vertices) towards the centroid."""
    xi0 = xi0.copy()
    centre = chart.xi_nodes.mean(axis=0)
    todo = np.arange(len(xi0))
    for t in (0.0, 0.02, 0.05, 0.1, 0.2, 0.4, 0.8):
        trial = xi0[todo] + t * (centre - xi0[todo])
        _, _, _, out = chart.evaluate(trial, order=0)
        xi0[todo[~out]] = trial[~out]
        todo = todo[out]
        if todo.size == 0:
            break
    return xi0


def newton_on_chart(chart, x: np.ndarray, xi0: np.ndarray, tol: float = 1e-12,
                    max_iter: int = 50, gtol: float = 1e-8) -> ChartNewton:
    """Minimise f(ξ) = ½|φ(ξ) − x|² on one chart for all rows of x, from ξ0 (Paper 2 App. A).

    Newton with the full Hessian (module docstring), Gauss–Newton where it is not positive
    definite, Armijo backtracking that also rejects points outside the chart's domain. A row
    stops when its step is below tol·diam(Ξ_κ), when no step decreases f, or after max_iter.
    It is ``converged`` if it ends inside the chart with |Dφᵀ(φ − x)| ≤ gtol·|Dφ|·(|φ − x| +
    diam(Ξ_κ)·|Dφ|) (a stationary point, not a point pinned to the hull boundary).
    """
    x = np.asarray(x, dtype=np.float64)
    xi = _inside_start(chart, np.asarray(xi0, dtype=np.float64))
    m, d = xi.shape
    L = _chart_scale(chart)
    X, T, S, out = chart.evaluate(xi, order=2)
    active = ~out
    n_iter = np.zeros(m, dtype=np.int64)
    history = []
    for _ in range(max_iter):
        rows = np.flatnonzero(active)
        if rows.size == 0:
            break
        r = X[rows] - x[rows]
        g = np.einsum("mai,mi->ma", T[rows], r)
        GN = np.einsum("mai,mbi->mab", T[rows], T[rows])
        H = GN + np.einsum("mabi,mi->mab", S[rows], r)
        p = _descent_step(H, GN, g)
        f0 = 0.5 * np.einsum("mi,mi->m", r, r)
        slope = np.einsum("ma,ma->m", g, p)
        step = np.full(m, np.nan)
        pending = np.ones(rows.size, bool)
        alpha = 1.0
        for _ls in range(30):
            idx = np.flatnonzero(pending)
            if idx.size == 0:
                break
            trial = xi[rows[idx]] + alpha * p[idx]
            Xt, Tt, St, outt = chart.evaluate(trial, order=2)
            rt = Xt - x[rows[idx]]
            ft = 0.5 * np.einsum("mi,mi->m", rt, rt)
            ok = ~outt & (ft <= f0[idx] + 1e-4 * alpha * slope[idx] + 1e-15 * (f0[idx] + L * L))
            acc = rows[idx[ok]]
            xi[acc], X[acc], T[acc], S[acc] = trial[ok], Xt[ok], Tt[ok], St[ok]
            step[acc] = alpha * np.linalg.norm(p[idx[ok]], axis=1)
            n_iter[acc] += 1
            pending[idx[ok]] = False
            alpha *= 0.5
        # rows whose line search failed stop; so do rows whose step was tiny
        stuck = rows[pending]
        active[stuck] = False
        done = rows[~pending][step[rows[~pending]] <= tol * L]
        active[done] = False
        history.append(step)
    r = X - x
    D = np.linalg.norm(r, axis=1)
    g = np.linalg.norm(np.einsum("mai,mi->ma", T, r), axis=1)
    tnorm = np.sqrt(np.einsum("mai,mai->m", T, T))
    converged = ~out & (g <= gtol * tnorm * (D + L * tnorm))
    # rows that started outside the chart never moved: they are not projections
    converged &= np.isfinite(D)
    return ChartNewton(xi, X, T, D, converged, n_iter, history)


def _descent_step(H: np.ndarray, GN: np.ndarray, g: np.ndarray) -> np.ndarray:
    """Newton step −H⁻¹g where H is positive definite, Gauss–Newton step −(DφᵀDφ)⁻¹g else."""
    p = np.empty_like(g)
    w = np.linalg.eigvalsh(H)
    wn = np.linalg.eigvalsh(GN)
    pd = w[:, 0] > 1e-8 * np.maximum(wn[:, -1], 1e-300)
    if pd.any():
        p[pd] = -np.linalg.solve(H[pd], g[pd][..., None])[..., 0]
    if (~pd).any():
        reg = GN[~pd] + 1e-12 * wn[~pd, -1][:, None, None] * np.eye(g.shape[1])
        p[~pd] = -np.linalg.solve(reg, g[~pd][..., None])[..., 0]
    return p


def candidate_pairs(atlas, x: np.ndarray, chart: Optional[int] = None):
    """(point row, chart, ψ_κ(x)) for every chart with ψ_κ(x) > 0 (or the given chart)."""
    m = x.shape[0]
    psi = atlas.patch_pu(x).tocsr()
    psi.eliminate_zeros()
    rows = np.repeat(np.arange(m), np.diff(psi.indptr))
    cols, vals = psi.indices.astype(np.int64), psi.data
    keep = vals > 0
    rows, cols, vals = rows[keep], cols[keep], vals[keep]
    if chart is not None:
        L = len(atlas.charts_)
        if not (0 <= int(chart) < L):
            raise InputError(f"chart = {chart!r} is invalid; the atlas has charts 0..{L - 1}.")
        sel = cols == int(chart)
        psi_k = np.zeros(m)
        psi_k[rows[sel]] = vals[sel]
        return np.arange(m), np.full(m, int(chart), dtype=np.int64), psi_k
    return rows, cols, vals


def project_pairs(atlas, x: np.ndarray, rows: np.ndarray, cols: np.ndarray,
                  tol: float = 1e-12, max_iter: int = 50) -> ChartNewton:
    """Newton projection of x[rows[i]] on chart cols[i] for every pair i (grouped by chart).

    Starts from the ξ of the chart's control point nearest to the point (ambient distance).
    """
    n, d = rows.size, atlas.charts_[0].xi_nodes.shape[1]
    D = x.shape[1]
    res = ChartNewton(np.full((n, d), np.nan), np.full((n, D), np.nan),
                      np.full((n, d, D), np.nan), np.full(n, np.inf), np.zeros(n, bool),
                      np.zeros(n, np.int64), [])
    for k, sel in label_groups(cols):
        ch = atlas.charts_[k]
        _, a = cKDTree(ch.control_points).query(x[rows[sel]], k=1)
        out = newton_on_chart(ch, x[rows[sel]], ch.xi_nodes[a], tol=tol, max_iter=max_iter)
        res.xi[sel], res.point[sel], res.tangents[sel] = out.xi, out.point, out.tangents
        res.distance[sel], res.converged[sel], res.n_iter[sel] = (
            out.distance, out.converged, out.n_iter)
    return res


def _check_points(atlas, x) -> np.ndarray:
    if not hasattr(atlas, "charts_"):
        raise InputError("the atlas has no charts yet; call atlas.build(points) (or partition "
                         "and build_charts) before projecting onto it.")
    X = np.asarray(x, dtype=np.float64)
    if X.ndim == 1:
        X = X[None, :]
    D = atlas.points_.shape[1]
    if X.ndim != 2 or X.shape[1] != D or not np.isfinite(X).all():
        raise InputError(f"points must be a finite (m, {D}) array (the atlas lives in R^{D}); "
                         f"got shape {np.shape(x)}.")
    return X


def _failure(x: np.ndarray, bad: np.ndarray, what: str) -> InputError:
    i = int(np.flatnonzero(bad)[0])
    return InputError(
        f"{what}: point {i} at {np.array2string(x[i], precision=6)} ({int(bad.sum())} point(s) "
        "in all) is outside every chart: no chart with ψ_κ(x) > 0 has a stationary point of "
        "|φ_κ(ξ) − x| inside its domain (the point is farther from the surface than the support "
        "of the patch partition of unity, about 2 sample spacings). Project only points near the "
        "surface, raise gamma_pu's support (lower gamma_pu / tol_pu), or pass on_failure='flag' "
        "to get converged=False rows instead.")


def closest_point(atlas, x, chart: Optional[int] = None, tol: float = 1e-12,
                  max_iter: int = 50, on_failure: str = "raise") -> Projection:
    """Closest-point projection of the rows of x (m, D) onto the atlas (Paper 2 App. A).

    Each point is projected on every chart with ψ_κ(x) > 0 (or only on ``chart``) by
    :func:`newton_on_chart`; the chart with the smallest converged distance wins (ties:
    largest ψ_κ(x)). on_failure='raise' raises InputError if some point has no converged
    projection; 'flag' returns it with converged=False (the best non-converged candidate, or
    chart = -1 and NaN if no chart applies).
    """
    if on_failure not in ("raise", "flag"):
        raise InputError(f"on_failure = {on_failure!r} is invalid; use 'raise' or 'flag'.")
    X = _check_points(atlas, x)
    m, D = X.shape
    rows, cols, psi = candidate_pairs(atlas, X, chart)
    res = project_pairs(atlas, X, rows, cols, tol=tol, max_iter=max_iter)
    dist = np.where(np.isfinite(res.distance), res.distance, np.inf)
    # sort pairs: converged first, then distance (relative ties → larger ψ), pick first per row
    key_d = np.floor(dist / (1e-9 * atlas.h_points_))  # distances within 1e-9 h tie
    order = np.lexsort((-psi, key_d, ~res.converged, rows))
    first = order[np.r_[True, rows[order][1:] != rows[order][:-1]]] if order.size else order
    d = atlas.charts_[0].xi_nodes.shape[1]
    out = Projection(np.full(m, -1, np.int64), np.full((m, d), np.nan), np.full((m, D), np.nan),
                     np.full(m, np.nan), None, np.zeros(m, bool), np.zeros(m, np.int64))
    r = rows[first]
    out.chart[r], out.xi[r], out.point[r] = cols[first], res.xi[first], res.point[first]
    out.distance[r], out.converged[r], out.n_iter[r] = (
        res.distance[first], res.converged[first], res.n_iter[first])
    out.distance[~np.isfinite(out.distance)] = np.nan
    if D == d + 1:  # hypersurface: a unit normal exists (surface in R^3, curve in R^2, ...)
        out.normal = np.full((m, D), np.nan)
        T = res.tangents[first]
        ok = np.isfinite(T).all(axis=(1, 2))
        n = dg.unit_normal(T[ok])
        away = X[r[ok]] - res.point[first][ok]
        flip = np.einsum("mi,mi->m", n, away) < 0
        n[flip] *= -1.0
        out.normal[r[ok]] = n
    if on_failure == "raise" and not out.converged.all():
        raise _failure(X, ~out.converged, "closest_point")
    return out


def blended_map(atlas, x, tol: float = 1e-12, max_iter: int = 50,
                on_failure: str = "raise") -> np.ndarray:
    """π(x) = Σ_{κ: ψ_κ(x) > 0} ψ_κ(x) φ_κ(ξ_κ(x)) for the rows of x (thesis §3.5, Eq. 3).

    ξ_κ(x) is the per-chart closest-point pre-image. Charts where Newton does not converge
    inside the domain (x's closest point lies outside that chart; ψ_κ(x) is then small) are
    left out and the remaining ψ_κ renormalised. Rows with no converged chart raise
    InputError, or are NaN with on_failure='flag'. Returns (m, D).
    """
    if on_failure not in ("raise", "flag"):
        raise InputError(f"on_failure = {on_failure!r} is invalid; use 'raise' or 'flag'.")
    X = _check_points(atlas, x)
    m, D = X.shape
    rows, cols, psi = candidate_pairs(atlas, X)
    res = project_pairs(atlas, X, rows, cols, tol=tol, max_iter=max_iter)
    w = np.where(res.converged, psi, 0.0)
    total = np.bincount(rows, weights=w, minlength=m)
    out = np.zeros((m, D))
    good = res.converged
    np.add.at(out, rows[good], w[good, None] * res.point[good])
    bad = total <= 0
    if bad.any() and on_failure == "raise":
        raise _failure(X, bad, "blended_map")
    with np.errstate(invalid="ignore", divide="ignore"):
        out /= total[:, None]
    out[bad] = np.nan
    return out
