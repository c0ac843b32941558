"""Triangles of a sampled surface, made from the charts of its atlas (for pictures and files).

A chart κ maps its control points J_κ to parametric points Ξ_κ ⊂ R²; the Delaunay
triangulation of Ξ_κ (as the charts' quadrature uses, :func:`pointatlas_atlas.chart.
chart_quadrature`) triangulates the surface near the patch. :func:`surface_triangles`
gathers the triangles of all charts into one surface, each place covered once:

1. each chart triangulates Ξ_κ with ties broken alike in every chart (a regular
   triangulation: the lifted heights |ξ|² get a perturbation of 10⁻⁶ h_κ² from the global
   point index, so the four cocircular corners of a grid square get the same diagonal in
   every chart whose embedding is an isometry, whatever its rotation), each triangle turned
   to the atlas's orientation (counter-clockwise in Ξ_κ times the chart's sign from
   :func:`pointatlas_atlas.orientation.orient_atlas`: outward normals on a closed surface);
2. triangles with a ghost node (beyond the boundary) are dropped, as in the quadrature, and
   so are those with an edge longer than ``max_edge`` × the local spacing (distance to the
   6th nearest point, the larger of the two ends) or of zero area (slivers on a hull);
3. candidates are ranked by ψ_κ at their centroid for the chart κ that made them (a
   triangle from the middle of a patch first; the same triangle from several charts once);
4. they are taken greedily, best first, when they overlap none taken: at each corner the
   triangle's angular sector in the tangent plane (the local PCA frame of
   :mod:`pointatlas_atlas.boundary`) is disjoint from those of the triangles already there,
   each edge has at most two triangles, and at a boundary point the empty angular gap that
   made it a boundary point (:func:`pointatlas_atlas.boundary.boundary_mask`) stays empty,
   so no triangle spans a hole or the region beyond an edge, ghosts or not.

Where the charts agree this is each chart's own triangulation; at the seams between charts
the first of two conflicting triangles wins and the other's place is filled by the next
candidate that fits. Measured on spheres of 800 and 20 000 points and open hemispheres: every
point in a triangle, each edge in two triangles (one along the boundary), Euler
characteristic 2 (sphere), 0 (hemisphere with a hole); 20 000 points in under 2 s. A point
can be in no triangle only when all its triangles touch ghosts (a cloud whose sampling
gaps were taken for holes, e.g. uniform random points on a sphere). No units: indices into
the points.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import ConvexHull, QhullError, cKDTree

from pointatlas.errors import InputError

#: longest edge of a kept triangle over the local spacing (6th-neighbour distance)
MAX_EDGE = 3.0
#: neighbours whose largest angular gap marks a boundary point (as
#: :func:`pointatlas_atlas.boundary.boundary_mask`, whose defaults the surface models use)
BOUNDARY_NEIGHBORS = 12
#: size of the tie-breaking perturbation of the lifted heights, relative to h²
TIE_BREAK = 1.0e-6


def _tie_weights(index: np.ndarray) -> np.ndarray:
    """A fixed pseudo-random number in [0, 1) per global point index (the same in every
    chart: Knuth's multiplicative hash)."""
    return ((np.asarray(index, np.uint64) * np.uint64(2654435761)) % np.uint64(2 ** 32)
            ).astype(np.float64) / 2.0 ** 32


def chart_triangles(xi: np.ndarray, index: np.ndarray) -> np.ndarray:
    """(m, 3) local indices of the regular triangulation of parametric points ``xi`` (n, 2):
    Delaunay with ties broken by the global ``index`` (module doc, step 1), each triangle
    counter-clockwise in ξ."""
    xi = np.asarray(xi, np.float64)
    if xi.ndim != 2 or xi.shape[1] != 2:
        raise InputError(f"a surface triangulation needs 2-D charts; got parametric points "
                         f"of shape {xi.shape}.")
    if len(xi) < 3:
        return np.zeros((0, 3), np.int64)
    c = xi - xi.mean(axis=0)
    h2 = float(cKDTree(c).query(c, k=2)[0][:, 1].mean()) ** 2 if len(c) > 1 else 1.0
    lifted = np.column_stack([c, (c * c).sum(axis=1) + TIE_BREAK * h2 * _tie_weights(index)])
    try:
        hull = ConvexHull(lifted, qhull_options="Qt Qbb")
    except QhullError:   # all points on a line: no triangle in this chart
        return np.zeros((0, 3), np.int64)
    t = hull.simplices[hull.equations[:, 2] < -1e-12].astype(np.int64)
    a, b, c = xi[t[:, 0]], xi[t[:, 1]], xi[t[:, 2]]
    cw = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
    t[cw] = t[cw][:, [0, 2, 1]]
    return t


def _edges(tri: np.ndarray) -> np.ndarray:
    """(3m, 2) sorted vertex pairs of the triangles' edges."""
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    return np.sort(e, axis=1)


def surface_triangles(atlas, n_real: int, max_edge: float = MAX_EDGE) -> np.ndarray:
    """(T, 3) int64 indices into the first ``n_real`` points of ``atlas.points_`` (the
    sampled points; the rest are ghost nodes): the triangles of the sampled surface, each
    once, without overlaps (module doc)."""
    P = np.asarray(atlas.points_, np.float64)
    n_real = int(n_real)
    if not 3 <= n_real <= len(P):
        raise InputError(f"surface_triangles: n_real = {n_real} must be between 3 and the "
                         f"atlas's {len(P)} points.")
    charts = getattr(atlas, "charts_", None)
    if not charts:
        raise InputError("surface_triangles needs a built atlas (atlas.build_charts first).")
    sign = np.asarray(getattr(atlas, "chart_orientation_", np.ones(len(charts))))
    tri, chart_of = [], []
    for k, chart in enumerate(charts):
        J = np.asarray(chart.node_index, np.int64)
        t = J[chart_triangles(chart.xi_nodes, J)]
        if sign[k] < 0:   # the chart's ξ orientation against the atlas's (orient_atlas)
            t = t[:, [0, 2, 1]]
        t = t[(t < n_real).all(axis=1)]
        tri.append(t)
        chart_of.append(np.full(len(t), k))
    tri, chart_of = np.concatenate(tri), np.concatenate(chart_of)
    tri, chart_of = _drop_bad(P, n_real, tri, chart_of, max_edge)
    if not len(tri):
        raise InputError("surface_triangles: the charts give no triangle of the sampled "
                         "points (too few points per chart?).")
    psi = atlas.patch_pu(P[tri].mean(axis=1)).tocsr()
    score = np.asarray(psi[np.arange(len(tri)), chart_of]).ravel()
    key = np.sort(tri, axis=1)
    order = np.lexsort((-score,) + tuple(key.T[::-1]))   # by triangle, best chart first
    key, tri, score = key[order], tri[order], score[order]
    first = np.ones(len(key), bool)
    first[1:] = (key[1:] != key[:-1]).any(axis=1)
    tri, score = tri[first], score[first]
    best = np.argsort(-score, kind="stable")
    return _greedy(P[:n_real], tri[best])


def _greedy(X: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """The candidates ``tri`` (best first) that do not overlap those taken before (module
    doc, step 4)."""
    from pointatlas_atlas.boundary import (DEFAULT_MIN_GAP_DEG, angular_gaps,
                                           nearest_neighbors, tangent_frames)

    nb, _ = nearest_neighbors(X, min(BOUNDARY_NEIGHBORS, len(X) - 1))
    frames = tangent_frames(X, nb)       # rows e1, e2, n: the boundary detection's frames
    gap, first, _ = angular_gaps(X, nb, frames)
    two_pi = 2 * np.pi

    def angle(v, a):
        """Direction of x_a − x_v in the tangent plane of v [rad]."""
        d = X[a] - X[v]
        return np.arctan2(np.einsum("ij,ij->i", d, frames[v, 1]),
                          np.einsum("ij,ij->i", d, frames[v, 0]))
    sectors = np.empty((len(tri), 3, 2))     # (start, counter-clockwise width) per corner
    for c in range(3):
        v, a, b = tri[:, c], tri[:, (c + 1) % 3], tri[:, (c + 2) % 3]
        ta, tb = angle(v, a), angle(v, b)
        w = np.mod(tb - ta, two_pi)
        flip = w > np.pi
        sectors[:, c, 0] = np.where(flip, tb, ta)
        sectors[:, c, 1] = np.where(flip, two_pi - w, w)
    edge = np.flatnonzero(gap > np.deg2rad(DEFAULT_MIN_GAP_DEG))   # the boundary points
    reserved = {int(p): (float(s), float(g)) for p, s, g in zip(
        edge, angle(edge, nb[edge, first[edge]]), gap[edge])}
    return tri[_accept(tri, sectors, len(X), reserved)]


def _accept(tri: np.ndarray, sectors: np.ndarray, n: int, reserved: dict) -> np.ndarray:
    """Greedy acceptance (in order) of the triangles whose sectors (start, width) [rad] at
    their three corners overlap neither an accepted triangle's there nor the ``reserved``
    sector of the vertex (point → (start, width)), and whose edges have < 2 triangles."""
    taken = [[reserved[p]] if p in reserved else [] for p in range(n)]
    edges: dict = {}
    ok = np.zeros(len(tri), bool)
    two_pi, eps = 2 * np.pi, 1e-9
    for i, t in enumerate(tri.tolist()):
        keys = [(min(t[p], t[q]), max(t[p], t[q])) for p, q in ((0, 1), (1, 2), (2, 0))]
        if any(edges.get(k, 0) >= 2 for k in keys):
            continue
        if any(_overlap(sectors[i, c], taken[t[c]], two_pi, eps) for c in range(3)):
            continue
        ok[i] = True
        for c in range(3):
            taken[t[c]].append((sectors[i, c, 0], sectors[i, c, 1]))
        for k in keys:
            edges[k] = edges.get(k, 0) + 1
    return ok


def _overlap(sector, others, two_pi: float, eps: float) -> bool:
    """Whether the arc ``sector`` (start, width) meets one of ``others`` in more than an end."""
    s1, w1 = sector
    for s2, w2 in others:
        d = (s2 - s1) % two_pi
        if d < w1 - eps or d + w2 > two_pi + eps:
            return True
    return False


def _drop_bad(P, n_real, tri, chart_of, max_edge):
    """Triangles without a too long edge or zero area (module doc, step 2)."""
    if not len(tri):
        return tri, chart_of
    X = P[:n_real]
    k = min(7, n_real)
    local = cKDTree(X).query(X, k=k)[0][:, -1]
    e = _edges(tri).reshape(3, -1, 2)
    length = np.linalg.norm(X[e[..., 0]] - X[e[..., 1]], axis=2)
    scale = np.maximum(local[e[..., 0]], local[e[..., 1]])
    short = (length <= max_edge * scale).all(axis=0)
    a, b, c = X[tri[:, 0]], X[tri[:, 1]], X[tri[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    longest = length.max(axis=0)
    flat = area <= 1e-6 * longest ** 2
    keep = short & ~flat
    return tri[keep], chart_of[keep]
