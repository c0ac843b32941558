"""Does each chart's share of the partition of unity stay inside the chart's domain?

An LME chart flattens towards the convex hull of its parameters Ξ_κ: there its image is the
chord between boundary points (Paper 1 §2.3; the ghost-node remark of Paper 2 §5.1), and
nothing beyond the hull is integrated at all. So ψ_κ must vanish a few spacings inside the
hull, which the chart margin is meant to ensure (``AtlasSettings.margin_for``). The margin is
counted in median point spacings, which an uneven sample does not show: on pyvista's
ParametricEllipsoid grid (meridians up to three spacings apart) a 3h margin let ψ_κ = 1 reach
the hull of 4 of 41 charts, and 0.57 % of the area was lost without a word.

The check here: ψ_κ at the vertices of the convex hull of Ξ_κ, at the points that are not on
the cloud's own boundary. A point on the cloud's boundary is a hull vertex of every chart that
holds it (the surface ends there, nothing is lost); a point that is inside the hull of some
other chart is an interior point of the surface, and the weight ψ_κ that chart κ gives it
lands on κ's flattened rim. Ghost nodes (Paper 1 §4.1.2) are not integrated and are skipped.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import ConvexHull, QhullError

#: ψ_κ at a hull vertex above this: the chart's rim carries partition-of-unity weight
#: (a sufficient margin gives 0 there; 1e-6 on a Fibonacci sphere with half the margin)
MAX_EDGE_PU = 0.01


def hull_vertices(xi: np.ndarray) -> np.ndarray:
    """Indices of the vertices of the convex hull of the parameters ξ (n, d)."""
    if xi.shape[1] == 1:
        return np.unique([int(np.argmin(xi[:, 0])), int(np.argmax(xi[:, 0]))])
    try:
        return ConvexHull(xi).vertices
    except QhullError:   # a degenerate (flat) parameter set: every node is on its rim
        return np.arange(len(xi))


def pu_at_chart_edges(node_sets: list[np.ndarray], xis: list[np.ndarray],
                      support: list[np.ndarray], n_points: int,
                      real: np.ndarray | None = None, boundary: np.ndarray | None = None
                      ) -> tuple[np.ndarray, np.ndarray]:
    """(edge ψ per chart (L,), the point (global index, −1 if none) where it is largest).

    ``node_sets[κ]`` the chart's nodes (global point indices), ``xis[κ]`` their parameters,
    ``support[κ]`` ψ_κ at them, ``real`` (N,) False at ghost nodes, ``boundary`` (N,) True on
    the cloud's own boundary (an open surface's edge can fall inside the convex hull of a
    chart whose domain is not convex there, so "a rim vertex of every chart" alone does not
    find it).
    """
    hulls = [hull_vertices(xi) for xi in xis]           # positions in J of each rim
    rims = [np.asarray(J)[h] for J, h in zip(node_sets, hulls)]
    inner = np.zeros(n_points, dtype=bool)     # inside the hull of at least one chart
    for J, rim in zip(node_sets, rims):
        is_rim = np.zeros(n_points, dtype=bool)
        is_rim[rim] = True
        inner[np.asarray(J)[~is_rim[J]]] = True
    if real is not None:
        inner &= np.asarray(real, dtype=bool)
    if boundary is not None:
        inner &= ~np.asarray(boundary, dtype=bool)
    edge, where = np.zeros(len(node_sets)), np.full(len(node_sets), -1, dtype=np.int64)
    for k, (J, psi, h, rim) in enumerate(zip(node_sets, support, hulls, rims)):
        v = h[inner[rim]]                               # the rim's vertices inside some chart
        if v.size:
            j = int(np.argmax(psi[v]))
            edge[k], where[k] = float(psi[v][j]), int(np.asarray(J)[v][j])
    return edge, where


def check_chart_edges(atlas, real: np.ndarray | None, refuse: bool) -> None:
    """Sets ``atlas.edge_pu_`` and ``atlas.edge_where_``; raises AtlasError if a chart's rim
    carries weight and ``refuse``. The cloud's boundary is found by
    :func:`.boundary.boundary_mask` for surfaces in R³ (else only the rim test applies)."""
    from pointatlas.errors import PointatlasError

    from .boundary import boundary_mask
    from .chart_repair import AtlasError

    P = atlas.points_
    on_edge = None
    if P.shape[1] == 3 and atlas.chart_dim_ == 2 and len(P) > 12:
        try:
            on_edge = boundary_mask(P, 12)
        except PointatlasError:      # no tangent planes to find an edge in: rims only
            on_edge = None
    atlas.edge_pu_, atlas.edge_where_ = pu_at_chart_edges(
        [c.node_index for c in atlas.charts_], [c.xi_nodes for c in atlas.charts_],
        atlas.support_, len(P), real, on_edge)
    if refuse and np.any(atlas.edge_pu_ > MAX_EDGE_PU):
        raise AtlasError(atlas_edge_message(atlas, refuse=True))


def atlas_edge_message(atlas, refuse: bool) -> str:
    return edge_message(atlas.points_, atlas.edge_pu_, atlas.edge_where_,
                        atlas.settings.margin_for(atlas.chart_dim_), refuse)


def edge_message(points: np.ndarray, edge: np.ndarray, where: np.ndarray, margin: float,
                 refuse: bool) -> str:
    """One line: how many charts carry weight on their rim, the worst, and what to try."""
    bad = np.flatnonzero(edge > MAX_EDGE_PU)
    k = int(bad[np.argmax(edge[bad])])
    at = ", ".join(f"{c:.3g}" for c in points[where[k]])
    head = (f"{len(bad)} of {len(edge)} charts carry partition-of-unity weight on the rim of "
            f"their domain (ψ up to {edge[k]:.2g} at a hull vertex of chart {k} near ({at})), "
            f"where a chart flattens to chords and past which nothing is integrated: the "
            f"chart margin of {margin:g} median spacings does not reach across the gaps of "
            f"this sample")
    if refuse:
        return (f"{head}; raise atlas.chart_margin (try {1.6 * margin:g}), or set "
                f"atlas.allow_failed_patches=true to keep the results flagged.")
    return head + " (results flagged)"
