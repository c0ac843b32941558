"""Global least-squares fit of the control points to samples of the manifold (Paper 2 App. B).

Paper 2 Appendix B (thesis L2579): given a good sampling X = {x_1, …, x_K} of M (K ≥ N),
find the control points P = {P_a} such that the blended atlas representation (thesis Eq. 3)

    I(x) = Σ_{κ ∈ N_x} ψ_κ(x) Σ_{a ∈ J_κ} p^κ_a(ξ_κ(x)) P_a = (M P)(x)

best fits the data, min_P ½ Σ_i |I(x_i) − x_i|², i.e. the sparse normal equations
MᵀM P = MᵀX with M_ia = Σ_κ ψ_κ(x_i) p^κ_a(ξ_κ(x_i)) (K × N). Unlike the per-chart fit
(:func:`chart.interpolating_control_points`, φ_κ(ξ_a) = x_a in each chart separately, so a
control point gets one position per chart), the global fit gives every control point one
position shared by all the charts holding it, and uses all the samples at once.

Pre-images ξ_κ(x_i): a sample that is control point a of chart κ takes its own embedded
coordinates Ξ_κ[a] (the chart's interpolation condition); any other sample its closest-point
pre-image on the current chart (Paper 2 App. A, :mod:`.projection`). Charts whose Newton does
not converge inside their domain, or whose LME is undefined there (hull vertices), are left
out and ψ renormalised over the rest, as in :func:`projection.blended_map`. A small Tikhonov
term ε|P − P⁰|² (ε relative to the diagonal of MᵀM) keeps control points that no sample
sees where they were. With ``iterations`` > 1 the pre-images are recomputed on the refitted
charts and the fit repeated (a fixed-point iteration; the paper does one solve).

Measured on a 600-point sphere (tests/plugins/atlas/test_surface_fit.py): the blend then
passes through the samples (7e-11) and the area error drops from 2.6e-2 to 5e-4, but the
chart-wise curvature integrals do not improve (Willmore 2e-3 against 3.6e-4 with the
per-chart fit): a shared control point cannot make every chart holding it interpolate, and
near the hull of Ξ_κ, where LME is nearly interpolating, a chart follows control points
fitted for its neighbours. Use a wide chart margin (≈ 5 h) with the global fit.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix, identity
from scipy.sparse.linalg import splu

from pointatlas.errors import InputError

from .chart import chart_derivatives
from .partition import label_groups
from .projection import candidate_pairs, project_pairs


@dataclass
class ControlPointFit:
    """Result of :func:`fit_control_points`."""

    control_points: np.ndarray    # (N, D) fitted P, shared by all charts
    matrix: object                # (K, N) sparse M at the pre-images used
    residual_before: np.ndarray   # (K,) |I(x_i) − x_i| with the charts' previous control points
    residual_after: np.ndarray    # (K,) |M P − x_i| with the fitted ones
    n_dropped: int                # samples no chart could represent (rows of M left empty)


def sample_pairs(atlas, samples: np.ndarray, sample_nodes: np.ndarray | None = None):
    """(row, chart, ψ_κ(x_i), ξ_κ(x_i)) for every sample and chart representing it.

    sample_nodes : (K,) global control-point index of each sample, or −1 (None: all −1); a
        sample that is control point a of chart κ uses Ξ_κ[a], the others are projected.
    ψ is renormalised over the pairs kept for each sample.
    """
    X = np.asarray(samples, dtype=np.float64)
    K = X.shape[0]
    nodes = np.full(K, -1, np.int64) if sample_nodes is None else np.asarray(sample_nodes,
                                                                              np.int64)
    rows, cols, psi = candidate_pairs(atlas, X)
    d = atlas.charts_[0].xi_nodes.shape[1]
    xi = np.full((rows.size, d), np.nan)
    ok = np.zeros(rows.size, bool)
    need = np.ones(rows.size, bool)
    for k, sel in label_groups(cols):
        where = np.full(atlas.points_.shape[0], -1, np.int64)
        c = atlas.charts_[k]
        where[c.node_index] = np.arange(c.node_index.size)
        node = nodes[rows[sel]]
        loc = np.where(node >= 0, where[np.maximum(node, 0)], -1)
        own = loc >= 0
        xi[sel[own]] = c.xi_nodes[loc[own]]
        ok[sel[own]] = True
        need[sel[own]] = False
    if need.any():
        idx = np.flatnonzero(need)
        res = project_pairs(atlas, X, rows[idx], cols[idx])
        xi[idx] = res.xi
        ok[idx] = res.converged
    return rows[ok], cols[ok], psi[ok], xi[ok]


def fit_matrix(atlas, n_samples: int, rows, cols, psi, xi):
    """M (K, N) with M_ia = Σ_κ ψ̂_κ(x_i) p^κ_a(ξ_κ(x_i)), ψ̂ renormalised over the pairs
    where the chart's LME exists. Returns (M, represented (K,) bool)."""
    N = atlas.points_.shape[0]
    r_all, c_all, v_all, keep_rows, keep_psi = [], [], [], [], []
    for k, sel in label_groups(cols):
        ch = atlas.charts_[k]
        b = ch.approximant.evaluate(xi[sel], order=0)
        inside = np.ones(sel.size, bool) if b.outside is None else ~b.outside
        counts = np.diff(b.indptr)
        r_all.append(np.repeat(rows[sel], counts))
        c_all.append(ch.node_index[b.indices])
        v_all.append(b.values * np.repeat(psi[sel], counts))
        keep_rows.append(rows[sel][inside])
        keep_psi.append(psi[sel][inside])
    total = np.bincount(np.concatenate(keep_rows), weights=np.concatenate(keep_psi),
                        minlength=n_samples)
    r, c, v = np.concatenate(r_all), np.concatenate(c_all), np.concatenate(v_all)
    represented = total > 0
    v = v / np.where(represented, total, 1.0)[r]
    M = coo_matrix((v, (r, c)), shape=(n_samples, N)).tocsr()
    return M, represented


def blended_at_pairs(atlas, n_samples: int, rows, cols, psi, xi) -> np.ndarray:
    """I(x_i) = Σ_κ ψ̂_κ φ_κ(ξ_κ(x_i)) with each chart's own control points (K, D)."""
    D = atlas.points_.shape[1]
    out = np.zeros((n_samples, D))
    total = np.zeros(n_samples)
    for k, sel in label_groups(cols):
        X, _, _, outside = atlas.charts_[k].evaluate(xi[sel], order=0)
        good = sel[~outside]
        np.add.at(out, rows[good], psi[good, None] * X[~outside])
        np.add.at(total, rows[good], psi[good])
    with np.errstate(invalid="ignore", divide="ignore"):
        return out / total[:, None]


def fit_control_points(atlas, samples, sample_nodes=None, regularization: float = 1e-10,
                       iterations: int = 1, update: bool = True) -> ControlPointFit:
    """Least-squares control points of the whole atlas for the samples (module docstring).

    samples : (K, D) points on the manifold (e.g. the atlas points, K = N, or a denser set).
    sample_nodes : (K,) control-point index of each sample or −1; None: when ``samples`` is
        the atlas's own point array (same shape and values) every sample is its own node.
    regularization : ε / mean(diag MᵀM) of the term keeping unseen control points in place.
    update : write P[J_κ] into every chart (and its fit_residual); rebuild the quadrature
        afterwards (``atlas.build_quadrature()``) for integrals on the fitted charts.
    """
    if not hasattr(atlas, "charts_"):
        raise InputError("fit_control_points needs built charts; call atlas.partition(points) "
                         "and atlas.build_charts() first.")
    X = np.asarray(samples, dtype=np.float64)
    N, D = atlas.points_.shape
    if X.ndim != 2 or X.shape[1] != D or not np.isfinite(X).all():
        raise InputError(f"samples must be a finite (K, {D}) array; got shape {np.shape(samples)}.")
    if isinstance(iterations, bool) or not isinstance(iterations, (int, np.integer)) \
            or iterations < 1:
        raise InputError(f"iterations = {iterations!r} is invalid; use an integer >= 1.")
    if sample_nodes is None and X.shape == atlas.points_.shape and np.array_equal(X, atlas.points_):
        sample_nodes = np.arange(N)
    P0 = atlas.points_.copy()
    previous = [(ch.control_points, ch.fit_residual) for ch in atlas.charts_]
    before = None
    P = P0
    for _ in range(int(iterations)):
        pairs = sample_pairs(atlas, X, sample_nodes)
        if before is None:
            before = np.linalg.norm(blended_at_pairs(atlas, X.shape[0], *pairs) - X, axis=1)
        M, represented = fit_matrix(atlas, X.shape[0], *pairs)
        A = (M.T @ M).tocsc()
        eps = float(regularization) * max(float(A.diagonal().mean()), 1e-300)
        A = A + eps * identity(N, format="csc")
        P = splu(A).solve(np.asarray(M.T @ X) + eps * P0)
        _write(atlas, P)
    after = np.linalg.norm(M @ P - X, axis=1)
    after[~represented] = np.nan
    if not update:
        for ch, (C, res) in zip(atlas.charts_, previous):
            ch.control_points, ch.fit_residual = C, res
    return ControlPointFit(P, M, before, after, int((~represented).sum()))


def _write(atlas, P: np.ndarray) -> None:
    """Give every chart the control points P[J_κ]; recompute its node residual."""
    for ch in atlas.charts_:
        ch.control_points = P[ch.node_index].copy()
        b = ch.approximant.evaluate(ch.xi_nodes, order=0)
        Xn, _, _ = chart_derivatives(b, ch.control_points, 0)
        ok = np.ones(len(Xn), bool) if b.outside is None else ~b.outside
        err = np.linalg.norm(Xn - atlas.points_[ch.node_index], axis=1)[ok]
        ch.fit_residual = float(np.max(err, initial=0.0))
