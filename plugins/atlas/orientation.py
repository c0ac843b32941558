"""One orientation for the whole atlas: chart signs propagated across the overlaps.

Each chart φ_κ comes with the orientation of its own embedding Ξ_κ, so two overlapping charts
may describe the same point with opposite normals (a per-chart "away from the centroid" test
cannot fix this on an open or flat surface). The atlas is oriented once, for every consumer
(the geometry's n, b and H, the shell's pressure):

1. At every control point a shared by charts κ and λ the oriented tangent frames are compared
   by the cosine of their unit d-vectors, c_a = (∧Dφ_κ)·(∧Dφ_λ) / (|∧Dφ_κ| |∧Dφ_λ|)
   = det(Dφ_κ Dφ_λᵀ) / sqrt(det a_κ det a_λ) (Cauchy–Binet; n_κ·n_λ for a hypersurface,
   any codimension otherwise). The overlap agrees when the mean of c_a over the shared
   points is > 0; an overlap is *decisive* when it shares at least :data:`MIN_SHARED` points
   and |mean c_a| ≥ :data:`MIN_AGREEMENT` (other overlaps are too small or too bent to say).
2. The charts of each connected group of decisive overlaps are visited along a maximum
   spanning tree (weight |Σ_a c_a|, the largest overlaps first) from the group's first chart;
   a chart whose overlap with its parent disagrees is flipped (s_κ = −s_parent).
3. Every decisive overlap, not only the tree's, is then checked: if one still disagrees
   (s_κ s_λ mean c < 0) there is no consistent orientation — a Möbius strip, a Klein bottle —
   and the atlas is marked non-orientable.
4. One sign per group: a hypersurface (D = d + 1) that encloses a volume — its vector area
   |∫ n dA| is below :data:`MAX_VECTOR_AREA` of its area, as for any closed surface, where it
   vanishes by the divergence theorem — gets outward normals, the sign of the enclosed volume
   V = ∫ (x − c)·n dA / D > 0; an open one follows the user's direction ``e``
   (∫ n·e dA > 0), or keeps its first chart's orientation when none is given.

Pure functions on arrays; :func:`orient_atlas` applies them to a built :class:`Atlas`.
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations
from typing import Optional, Sequence

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import breadth_first_order, connected_components, minimum_spanning_tree

from pointatlas.errors import InputError

#: an overlap decides the relative orientation of two charts with at least this many shared
#: points where both charts are defined ...
MIN_SHARED = 3
#: ... and a mean cosine of their tangent d-vectors of at least this size (±1 on smooth charts)
MIN_AGREEMENT = 0.5
#: a hypersurface whose vector area |∫ n dA| is below this fraction of its area encloses a
#: volume (0 on a closed surface; 1 on a flat disc, 1/2 on a hemisphere, (1 − cos θ)/2 on a
#: sphere missing a cap of half-angle θ)
MAX_VECTOR_AREA = 0.05
#: ... and then its enclosed volume decides the sign when |∫(x−c)·n dA| ≥ this × area × radius
MIN_VOLUME = 1e-3
#: a user direction decides when |∫ n·e dA| ≥ this × |∫ n dA| (e not within ~87° of tangent)
MIN_DIRECTION = 0.05


@dataclass
class Orientation:
    """Result of :func:`orient_charts`: one sign per chart and how the side was chosen."""

    signs: np.ndarray         # (L,) ±1: multiply chart κ's normal by signs[κ]
    orientable: bool          # False: some decisive overlap disagrees after propagation
    mode: str                 # 'outward', 'direction', 'first_chart' (mixed: joined by '+'),
    #                           'none' (non-orientable)
    direction: Optional[np.ndarray]  # the user direction used, if any
    n_conflicts: int          # decisive overlaps that disagree after propagation
    n_overlaps: int           # decisive overlaps (chart pairs)
    n_groups: int             # connected groups of charts (oriented independently)


def frame_vectors(T: np.ndarray) -> np.ndarray:
    """Unit d-vectors ∧Dφ / |∧Dφ| of tangent frames T (m, d, D): (m, C(D, d)) Plücker
    coordinates, the d×d minors det T[:, :, I] over sorted column sets I. Rows with a
    degenerate frame are NaN. For a surface in R^3 this is the unit normal up to a fixed
    permutation and signs, so dot products of these vectors are n_κ·n_λ."""
    T = np.asarray(T, dtype=np.float64)
    d, D = T.shape[1], T.shape[2]
    W = np.stack([np.linalg.det(T[:, :, list(cols)]) for cols in combinations(range(D), d)],
                 axis=1)
    norm = np.linalg.norm(W, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 0, W / norm, np.nan)


def _n_minors(d: int, D: int) -> int:
    return sum(1 for _ in combinations(range(D), d))


def overlap_agreement(node_index: Sequence[np.ndarray], frames: Sequence[np.ndarray],
                      n_nodes: int) -> tuple[csr_matrix, csr_matrix]:
    """(Σ_a c_a, number of shared points) for every pair of charts, as (L, L) sparse matrices.

    node_index[κ] (n_κ,) global ids of chart κ's points; frames[κ] (n_κ, C) their unit
    d-vectors (:func:`frame_vectors`), NaN rows where the chart is undefined (not counted).
    """
    L = len(node_index)
    rows, cols, vals = [], [], []
    for k, (J, W) in enumerate(zip(node_index, frames)):
        ok = np.isfinite(W).all(axis=1)
        rows.append(np.full(int(ok.sum()), k))
        cols.append(np.asarray(J)[ok])
        vals.append(W[ok])
    r, c, V = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    B = csr_matrix((np.ones(r.size), (r, c)), shape=(L, n_nodes))
    count = (B @ B.T).tocsr()
    S = csr_matrix((L, L))
    for j in range(V.shape[1]):
        M = csr_matrix((V[:, j], (r, c)), shape=(L, n_nodes))
        S = S + M @ M.T
    return S.tocsr(), count


def propagate_signs(S: csr_matrix, count: csr_matrix) -> tuple[np.ndarray, np.ndarray, int, int]:
    """(signs (L,), group (L,), n_conflicts, n_overlaps): steps 2–3 of the module doc."""
    L = S.shape[0]
    S, count = S.tocoo(), count.tocoo()
    key = count.row.astype(np.int64) * L + count.col     # count's entries at S's positions
    order = np.argsort(key)
    at = np.searchsorted(key[order], S.row.astype(np.int64) * L + S.col)
    n_shared = count.data[order][np.minimum(at, max(key.size - 1, 0))] if key.size else S.data
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = S.data / np.maximum(n_shared, 1)
    decisive = ((S.row < S.col) & (n_shared >= MIN_SHARED) & (np.abs(mean) >= MIN_AGREEMENT))
    a, b, s = S.row[decisive], S.col[decisive], S.data[decisive]
    # maximum spanning tree: minimum over positive weights that decrease with |Σ c|
    weight = (np.abs(s).max(initial=0.0) + 1.0) - np.abs(s)
    G = csr_matrix((weight, (a, b)), shape=(L, L))
    tree = minimum_spanning_tree(G)
    tree = (tree + tree.T).tocsr()
    sign_of = csr_matrix((np.sign(s), (a, b)), shape=(L, L))
    sign_of = (sign_of + sign_of.T).tocsr()
    n_groups, group = connected_components(tree, directed=False)
    signs = np.ones(L)
    for g in range(n_groups):
        root = int(np.flatnonzero(group == g)[0])
        order, parent = breadth_first_order(tree, root, directed=False)
        for k in order[1:]:
            signs[k] = signs[parent[k]] * sign_of[parent[k], k]
    conflicts = int(np.count_nonzero(signs[a] * signs[b] * s < 0))
    return signs, group, conflicts, int(a.size)


def orient_charts(node_index: Sequence[np.ndarray], frames: Sequence[np.ndarray], n_nodes: int,
                  sums: Optional[dict] = None, direction=None) -> Orientation:
    """Chart signs for one orientation of the atlas (module doc, steps 1–4).

    sums : per-chart quadrature sums of the *unsigned* chart normals n_κ of a hypersurface,
        ``area`` Σ w (L,), ``vector_area`` Σ w n (L, D), ``first_moment`` Σ w x (L, D),
        ``second_moment`` Σ w |x|² (L,), ``flux`` Σ w x·n (L,) (w: quadrature weights);
        None (not a hypersurface): each group keeps its first chart's orientation.
    direction : (D,) the side the normals of an open surface should face, or None.
    Raises InputError when ``direction`` cannot decide (tangent to the surface on average).
    """
    S, count = overlap_agreement(node_index, frames, n_nodes)
    signs, group, conflicts, n_overlaps = propagate_signs(S, count)
    n_groups = int(group.max()) + 1 if group.size else 0
    e = None if direction is None else np.asarray(direction, dtype=np.float64)
    if conflicts:
        return Orientation(signs, False, "none", e, conflicts, n_overlaps, n_groups)
    modes = []
    for g in range(n_groups):
        k = group == g
        mode, flip = _group_side(signs[k], {n: v[k] for n, v in sums.items()}
                                 if sums is not None else None, e)
        signs[k] *= -1.0 if flip else 1.0
        modes.append(mode)
    return Orientation(signs, True, "+".join(sorted(set(modes))) or "first_chart", e, 0,
                       n_overlaps, n_groups)


def _group_side(s: np.ndarray, sums: Optional[dict], e: Optional[np.ndarray]
                ) -> tuple[str, bool]:
    """(mode, flip) for one connected group of charts already oriented alike by ``s``."""
    if sums is None:
        return "first_chart", False
    A = float(sums["area"].sum())
    if A <= 0:
        return "first_chart", False
    N = s @ sums["vector_area"]                      # ∫ n dA
    if np.linalg.norm(N) < MAX_VECTOR_AREA * A:
        c = sums["first_moment"].sum(axis=0) / A
        flux = float(s @ sums["flux"] - c @ N)       # ∫ (x − c)·n dA = D V
        radius = np.sqrt(max(float(sums["second_moment"].sum()) / A - float(c @ c), 0.0))
        if abs(flux) >= MIN_VOLUME * A * radius:
            return "outward", flux < 0
    if e is None:
        return "first_chart", False
    if e.shape != N.shape:
        raise InputError(f"atlas.orientation = {e.tolist()} has {e.size} component(s); the "
                         f"points are in R^{N.size}: give a direction with {N.size}.")
    t = float(N @ e) / np.linalg.norm(e)
    if abs(t) < MIN_DIRECTION * np.linalg.norm(N):
        mean = N / np.linalg.norm(N)
        raise InputError(
            f"atlas.orientation = {e.tolist()} is (nearly) tangent to this open surface on "
            f"average (∫ n·e dA = {t:.3g} of |∫ n dA| = {np.linalg.norm(N):.3g}), so it "
            "cannot choose a side: give the direction the surface faces, e.g. "
            f"atlas.orientation={np.round(mean, 3).tolist()} or its opposite.")
    return "direction", t < 0


def frame_masks(atlas) -> list[np.ndarray]:
    """Per chart, the control points whose frames decide the orientation: those where the
    chart is used (ψ_κ > tol_pu: on the margin towards its hull an LME chart flattens to the
    chord and its tangents turn, Paper 1 §2.3) and that another chart uses too (the others
    decide nothing)."""
    uses = [np.asarray(psi) > atlas.settings.tol_pu for psi in atlas.support_]
    n_users = np.bincount(np.concatenate([c.node_index[u] for c, u in zip(atlas.charts_, uses)]),
                          minlength=atlas.points_.shape[0])
    return [use & (n_users[c.node_index] > 1) for c, use in zip(atlas.charts_, uses)]


def chart_frames(chart, mask: np.ndarray) -> np.ndarray:
    """(n_κ, C(D, d)) unit d-vectors of chart κ's own frame at its control points in
    ``mask`` (order-1 derivatives at Ξ_κ), NaN elsewhere and where the chart is undefined."""
    used = np.flatnonzero(mask)
    W = np.full((len(chart.node_index), _n_minors(chart.xi_nodes.shape[1],
                                                  chart.control_points.shape[1])), np.nan)
    if used.size:
        _, T, _, outside = chart.evaluate(chart.xi_nodes[used], order=1)
        W[used] = frame_vectors(T)
        W[used[np.asarray(outside, bool)]] = np.nan
    return W


def orient_atlas(atlas, frames: Optional[Sequence[np.ndarray]] = None) -> Orientation:
    """Orient a built atlas (charts and quadrature): sets ``chart_orientation_`` (L,) ±1,
    ``orientation_`` (str: 'outward', 'first_chart', the direction used as '[nx, ny, nz]',
    or 'none'), ``orientable_`` (bool) and ``orientation_report_`` (the :class:`Orientation`).

    Frames at the control points (:func:`chart_frames` on :func:`frame_masks`; ``frames``:
    already computed, e.g. by the patch tasks of a distributed run); the quadrature sums use
    the chart normals at its Gauss points (hypersurfaces only).
    """
    from .differential_geometry import unit_normal

    charts, quad = atlas.charts_, atlas.quadrature_
    if frames is None:
        frames = [chart_frames(c, m) for c, m in zip(charts, frame_masks(atlas))]
    d, D = charts[0].xi_nodes.shape[1], charts[0].control_points.shape[1]
    sums = None
    if D == d + 1:
        keys = ("area", "vector_area", "first_moment", "second_moment", "flux")
        parts = {k: [] for k in keys}
        for q in quad:
            w, x = q.weights, q.positions
            n = unit_normal(q.tangents) if len(w) else np.zeros((0, D))
            for k, v in zip(keys, (w.sum(), w @ n, w @ x, w @ np.einsum("ij,ij->i", x, x),
                                   w @ np.einsum("ij,ij->i", x, n))):
                parts[k].append(v)
        sums = {k: np.asarray(v, dtype=np.float64) for k, v in parts.items()}
    direction = getattr(atlas.settings, "orientation", None)
    o = orient_charts([c.node_index for c in charts], frames, atlas.points_.shape[0], sums,
                      direction)
    atlas.chart_orientation_ = o.signs
    atlas.orientable_ = o.orientable
    atlas.orientation_ = (o.mode if o.mode != "direction" or o.direction is None
                          else "[" + ", ".join(f"{v:g}" for v in o.direction) + "]")
    atlas.orientation_report_ = o
    return o


def non_orientable_message(o: Orientation) -> str:
    """Why a quantity that needs a normal is refused on a non-orientable atlas (one line)."""
    return (f"this point cloud is not orientable ({o.n_conflicts} of {o.n_overlaps} chart "
            "overlaps disagree however the charts are flipped, as on a Möbius strip), so it "
            "has no consistent normal: normals, the signed mean curvature and pressure loads "
            "are undefined. Orientation-free quantities (area, gaussian_curvature, "
            "mean_curvature_squared for the Willmore energy) still work.")
