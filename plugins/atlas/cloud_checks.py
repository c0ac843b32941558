"""Is a point cloud one smooth surface at the chart scale? Components, creases, sheets.

An atlas of LME charts (thesis §3) assumes that the cloud samples one smooth, connected
2-manifold finely enough that every k-NN neighbourhood is a disc on which the surface is a
smooth graph. Three checks, each a k-NN query and a few vectorised operations (pure
functions of arrays; the median spacing h = median nearest-neighbour distance, as in
``Atlas.partition``):

1. **Components** of the symmetrised k-NN graph (k = ``graph_neighbors``, the graph METIS
   partitions), with every edge longer than :data:`MAX_EDGE` · h cut. For a Poisson
   (uniform random) sampling P(nearest neighbour > c h) = 2^(−c²), so at c = 5 not one of
   10⁶ points loses its nearest edge; a gap wider than the k-th neighbour distance (≈ 1.7 h
   quasi-uniform, ≈ 3.6 h random, k = 10) separates components. A component with fewer than
   :data:`MIN_COMPONENT_POINTS` points (less than two local neighbourhoods: no chart and no
   quadric fit can be checked on it) is dropped and counted as isolated points; more than
   :data:`MAX_ISOLATED_FRACTION` of the cloud isolated is not a few outliers but a sampling
   too uneven for one chart scale (pyvista's airplane.ply: the vertices of a CAD mesh, dense
   along its edges, 5 h or more apart on its large flat triangles; 54 % isolated) and refused.
2. **Creases.** At each point the k = :data:`LOCAL_NEIGHBORS` nearest points (itself
   included), in the frame of their principal axes (local PCA; the normal is the axis of
   least variance), are fitted by a quadric height z = c₀ + c₁x + c₂y + c₃x² + c₄xy + c₅y²
   (least squares, Hoppe et al. 1992 for the PCA plane, the osculating-jet fit of Cazals &
   Pouget 2005 for the quadric). The RMS residual in units of ρ, the distance to the k-th
   neighbour, is scale free: on a smooth surface of curvature κ it is the quartic term,
   about (ρκ)³/105 for a circular arc (Legendre P₄ part of x⁴/8), plus sampling noise; on a
   crease whose normal turns by φ it is that of |x| tan(φ/2) by a parabola, ≈ 0.07 tan(φ/2),
   however fine the sampling. :data:`MAX_RESIDUAL` = 0.035 lies between the two as measured:
   smooth clouds, 0.005 (pyvista's sphere.ply, integer coordinates), 0.012 (torus with 19
   spacings round the tube), 0.028 (genus-2 tube with 24 spacings round, sampling noise);
   the edges of a sampled cube 0.076, pyvista's nut.ply median 0.072. It flags creases of
   φ ≳ 55° (ρκ ≳ 1.5 on a smooth surface: curvature radius below ~1.5 spacings, not
   resolved by any chart). The normal jump between neighbours does not separate these:
   a smooth tube with 27 spacings round has jumps up to 42° between 6 nearest neighbours.
3. **Non-manifold points** (the neighbourhood is not a disc: sheets meeting along a line,
   or two sheets closer than ρ). A disc neighbourhood, creased or not, is the graph of a
   height over some plane — a crease over its bisector, with slope ≤ tan(φ/2); a junction
   of three half-planes or two parallel sheets is a graph over none: some pair of points
   lies (almost) above one another for every plane. Tested on the points that fail (2)
   only, with the PCA normals of the point's neighbours as candidate planes: the point is
   non-manifold if for every candidate some pair of neighbours (at least h/2 apart) has
   |Δz| / |Δxy| > :data:`MAX_SLOPE` (tan 70°; a crease with φ > 140°, a knife edge, counts as
   two sheets). Tested on the same k neighbours: with more (20), the 1-spacing-wide top
   face of nut.ply, between the hole and the chamfer, reads as a knife edge.

One line per refusal (:func:`refusal`): crease points (with the non-manifold ones, if any,
named after them) or non-manifold points, with up to three far-apart locations.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

#: k-NN edges longer than this many median spacings h are cut (P = 2^(−25) per point on a
#: Poisson sampling)
MAX_EDGE = 5.0
#: points of the local PCA / quadric fit, the point included (6 coefficients: 6 dof left)
LOCAL_NEIGHBORS = 12
#: components with fewer points are isolated points: dropped and counted
MIN_COMPONENT_POINTS = 2 * LOCAL_NEIGHBORS
#: a cloud with more isolated points than this fraction is refused (too unevenly sampled)
MAX_ISOLATED_FRACTION = 0.05
#: largest RMS quadric residual / ρ of a smooth neighbourhood
MAX_RESIDUAL = 0.035
#: a neighbourhood steeper than this over every candidate plane is not a disc (tan 70°)
MAX_SLOPE = float(np.tan(np.radians(70.0)))
#: rough points classified per block (memory: block · k² · (k+1) doubles)
_BLOCK = 2000


def median_spacing(points: np.ndarray) -> float:
    """h: the median nearest-neighbour distance of the (N, D) points (length units)."""
    d, _ = cKDTree(points).query(points, k=2)
    return float(np.median(d[:, 1]))


@dataclass
class Components:
    """Connected components of the cut k-NN graph (:func:`cloud_components`)."""

    labels: np.ndarray   # (N,) component of each point, 0..n-1 by decreasing size; −1: isolated
    sizes: np.ndarray    # (n,) points per component
    centroids: np.ndarray  # (n, D) mean of each component's points
    h: float             # median spacing used for the cut

    @property
    def n_isolated(self) -> int:
        return int((self.labels < 0).sum())


def cloud_components(points: np.ndarray, n_neighbors: int = 10, max_edge: float = MAX_EDGE,
                     min_size: int = MIN_COMPONENT_POINTS, knn=None) -> Components:
    """Components of the symmetrised k-NN graph with edges longer than ``max_edge`` · h cut.

    Components with fewer than ``min_size`` points are labelled −1 (isolated). Returns
    :class:`Components`, largest component first. ``knn``: (distances, indices) of a k-NN
    query of the points on themselves with at least ``n_neighbors`` + 1 columns, if done.
    """
    P = np.asarray(points, dtype=np.float64)
    n = P.shape[0]
    k = min(int(n_neighbors), n - 1)
    if k < 1:
        return Components(np.full(n, -1), np.zeros(0, int), np.zeros((0, P.shape[1])), 0.0)
    d, nb = knn if knn is not None else cKDTree(P).query(P, k=k + 1)
    d, nb = d[:, :k + 1], nb[:, :k + 1]
    h = float(np.median(d[:, 1]))
    keep = d[:, 1:] <= max_edge * h
    rows = np.repeat(np.arange(n), k)[keep.ravel()]
    A = coo_matrix((np.ones(rows.size), (rows, nb[:, 1:].ravel()[keep.ravel()])), shape=(n, n))
    _, raw = connected_components(A, directed=False)
    raw_sizes = np.bincount(raw)
    order = np.argsort(-raw_sizes, kind="stable")
    big = order[raw_sizes[order] >= min_size]
    new = np.full(raw_sizes.size, -1)
    new[big] = np.arange(big.size)
    labels = new[raw]
    sizes = raw_sizes[big]
    centroids = np.array([P[labels == c].mean(axis=0) for c in range(big.size)]
                         ).reshape(big.size, P.shape[1])
    return Components(labels, sizes, centroids, h)


def quadric_residuals(points: np.ndarray, k: int = LOCAL_NEIGHBORS, knn=None):
    """RMS residual / ρ of the least-squares quadric height over each point's PCA plane.

    Returns (residual (N,), PCA normals (N, 3), neighbour indices (N, k)); ρ is the distance
    to the k-th neighbour. Needs N ≥ k and D = 3. ``knn``: a k-NN query with ≥ k columns.
    """
    P = np.asarray(points, dtype=np.float64)
    d, nb = knn if knn is not None else cKDTree(P).query(P, k=k)
    d, nb = d[:, :k], nb[:, :k]
    L = (P[nb] - P[:, None, :]) / np.maximum(d[:, -1], 1e-300)[:, None, None]   # (N, k, 3)
    m = L.mean(axis=1)
    C = np.matmul(L.transpose(0, 2, 1), L) / k - m[:, :, None] * m[:, None, :]
    _, V = np.linalg.eigh(C)               # columns by increasing variance: V[:, :, 0] = normal
    xyz = np.matmul(L, V)
    z, y, x = xyz[..., 0], xyz[..., 1], xyz[..., 2]
    A = np.empty(z.shape + (6,))
    A[..., 0], A[..., 1], A[..., 2] = 1.0, x, y
    A[..., 3], A[..., 4], A[..., 5] = x * x, x * y, y * y
    At = A.transpose(0, 2, 1)
    c = np.linalg.solve(np.matmul(At, A) + 1e-12 * np.eye(6), np.matmul(At, z[..., None]))
    r = z - np.matmul(A, c)[..., 0]
    return np.sqrt((r * r).mean(axis=1)), V[:, :, 0], nb


def not_a_graph(points: np.ndarray, normals: np.ndarray, nb: np.ndarray, which: np.ndarray,
                h: float, max_slope: float = MAX_SLOPE) -> np.ndarray:
    """True for each point of ``which`` whose neighbourhood is steeper than ``max_slope``
    over every candidate plane (normal to one of its neighbours' PCA normals).

    The slope of a pair (i, j) over the plane of normal m is |Δz| / |Δxy| with z = x·m;
    pairs closer than h/2 are ignored (sampling noise).
    """
    out = np.zeros(len(which), dtype=bool)
    for s in range(0, len(which), _BLOCK):
        w = which[s:s + _BLOCK]
        L = points[nb[w]] - points[w][:, None, :]                      # (b, k, 3)
        D = L[:, :, None, :] - L[:, None, :, :]                        # (b, k, k, 3)
        far = np.einsum("bijc,bijc->bij", D, D) >= (0.5 * h) ** 2
        M = normals[nb[w]]                                            # (b, m, 3) candidates
        dz = np.abs(np.einsum("bijc,bmc->bmij", D, M))                # (b, m, k, k)
        dxy2 = np.einsum("bijc,bijc->bij", D, D)[:, None] - dz * dz
        steep = (dz * dz > max_slope ** 2 * np.maximum(dxy2, 0.0)) & far[:, None]
        out[s:s + _BLOCK] = steep.any(axis=(2, 3)).all(axis=1)
    return out


@dataclass
class SurfaceDefects:
    """Points of one component that are not on a smooth disc (:func:`surface_defects`)."""

    crease: np.ndarray       # (N,) bool: a crease or corner (rough, but a graph over a plane)
    nonmanifold: np.ndarray  # (N,) bool: the neighbourhood is not a disc
    residual: np.ndarray     # (N,) quadric residual / ρ


def surface_defects(points: np.ndarray, k: int = LOCAL_NEIGHBORS,
                    max_residual: float = MAX_RESIDUAL, max_slope: float = MAX_SLOPE, knn=None
                    ) -> SurfaceDefects:
    """Crease and non-manifold points of one connected component of a cloud in R³.

    ``knn``: (distances, indices) of a k-NN query of the points on themselves (≥ k columns).
    """
    P = np.asarray(points, dtype=np.float64)
    n = P.shape[0]
    if n < k or P.shape[1] != 3:
        none = np.zeros(n, dtype=bool)
        return SurfaceDefects(none, none.copy(), np.zeros(n))
    knn = knn if knn is not None else cKDTree(P).query(P, k=k)
    h = float(np.median(knn[0][:, 1]))
    residual, normals, nb = quadric_residuals(P, k, knn)
    rough = np.flatnonzero(residual > max_residual)
    nonmanifold = np.zeros(n, dtype=bool)
    nonmanifold[rough] = not_a_graph(P, normals, nb, rough, h, max_slope)
    crease = np.zeros(n, dtype=bool)
    crease[rough] = ~nonmanifold[rough]
    return SurfaceDefects(crease, nonmanifold, residual)


def spread_out(points: np.ndarray, n: int = 3) -> np.ndarray:
    """Up to n of the points, far apart (greedy farthest-point from the first)."""
    P = np.asarray(points, dtype=np.float64)
    if len(P) == 0:
        return P
    pick = [0]
    dist = np.linalg.norm(P - P[0], axis=1)
    while len(pick) < min(n, len(P)):
        pick.append(int(np.argmax(dist)))
        dist = np.minimum(dist, np.linalg.norm(P - P[pick[-1]], axis=1))
    return P[pick]


def where(points: np.ndarray, n: int = 3) -> str:
    """'(x, y, z), (x, y, z), ...': up to n far-apart locations, 3 significant digits."""
    return ", ".join("(" + ", ".join(f"{v:.3g}" for v in p) + ")"
                     for p in spread_out(points, n))


def _count_where(points: np.ndarray, mask: np.ndarray) -> str:
    return f"{int(mask.sum())} points (of {len(mask)}), e.g. near {where(points[mask])}"


def defects_message(points: np.ndarray, crease: np.ndarray, nonmanifold: np.ndarray,
                    h: float) -> str | None:
    """The one-line refusal of a cloud with creases or non-disc neighbourhoods, or None.

    Creases: the issue-16 message ("this cloud has creases; ..."), the non-manifold points
    appended; non-manifold points alone: "this cloud is not a manifold at the chart scale".
    """
    sheets = (f"neighbourhoods that are not a disc (sheets meeting, or two sheets closer than "
              f"~{2 * h:.3g}, twice the median spacing)")
    fix = ("Give a cloud of one smooth surface sampled a few spacings apart across its thin "
           "parts, or split it along its creases and junctions and run each smooth piece as "
           "its own file.")
    if crease.any():
        more = (f"; and {_count_where(points, nonmanifold)} with {sheets}"
                if nonmanifold.any() else "")
        return (f"this cloud has creases; the curvature integrals of a smooth atlas do not "
                f"apply there: {int(crease.sum())} points on creases (of {len(crease)}), e.g. "
                f"near {where(points[crease])}{more}. {fix}")
    if nonmanifold.any():
        return (f"this cloud is not a manifold at the chart scale: "
                f"{_count_where(points, nonmanifold)} have {sheets}. {fix}")
    return None


def components_message(comp: Components) -> str:
    """Count, sizes and centroids of the components (for logs and refusals)."""
    parts = ", ".join(f"{s} points near ({', '.join(f'{v:.3g}' for v in c)})"
                      for s, c in zip(comp.sizes[:5], comp.centroids[:5]))
    more = f", and {len(comp.sizes) - 5} more" if len(comp.sizes) > 5 else ""
    return (f"{len(comp.sizes)} connected components (k-NN graph, edges > {MAX_EDGE:g} h = "
            f"{MAX_EDGE * comp.h:.3g} cut): {parts}{more}")


@dataclass
class CloudCheck:
    """Result of :func:`check_cloud`."""

    components: Components
    crease: np.ndarray       # (N,) bool
    nonmanifold: np.ndarray  # (N,) bool


def check_cloud(points: np.ndarray, n_neighbors: int = 10, surface: bool = True
                ) -> CloudCheck:
    """Components of the cloud and, if ``surface`` (a 2-manifold in R³ is expected), the
    crease and non-manifold points of each component (isolated points: neither)."""
    P = np.asarray(points, dtype=np.float64)
    knn = cKDTree(P).query(P, k=min(len(P), max(int(n_neighbors) + 1, LOCAL_NEIGHBORS)))
    comp = cloud_components(P, n_neighbors, knn=knn)
    crease = np.zeros(len(P), dtype=bool)
    nonmanifold = np.zeros(len(P), dtype=bool)
    if surface and P.shape[1] == 3:
        for c in range(len(comp.sizes)):
            idx = np.flatnonzero(comp.labels == c)
            # one component spanning the cloud: its neighbourhoods are the cloud's
            d = surface_defects(P[idx], knn=knn if len(idx) == len(P) else None)
            crease[idx], nonmanifold[idx] = d.crease, d.nonmanifold
    return CloudCheck(comp, crease, nonmanifold)


def refusal(points: np.ndarray, check: CloudCheck) -> str | None:
    """The one-line reason ``points`` cannot carry smooth atlases (one per component), or
    None: too many isolated points, creases, or non-disc neighbourhoods."""
    comp = check.components
    n = len(comp.labels)
    if comp.n_isolated > MAX_ISOLATED_FRACTION * n or not len(comp.sizes):
        iso = comp.labels < 0
        return (f"this cloud is too unevenly sampled for one chart scale: {comp.n_isolated} "
                f"of its {n} points are isolated (in groups of fewer than "
                f"{MIN_COMPONENT_POINTS} points, more than {MAX_EDGE:g} h = "
                f"{MAX_EDGE * comp.h:.3g} from the rest, h the median spacing), e.g. near "
                f"{where(np.asarray(points)[iso])}. Resample the surface quasi-uniformly (e.g. "
                "points spread over a mesh's faces, not only its vertices).")
    return defects_message(np.asarray(points), check.crease, check.nonmanifold, comp.h)


def verdict(points: np.ndarray, check: CloudCheck, name: str, allow_creases: bool = False
            ) -> tuple[str | None, str | None]:
    """(refusal, kept) for the cloud called ``name``: the one-line reason to refuse it (None
    if it may run) and, when ``allow_creases`` keeps a cloud whose only defect is crease
    points, the reason the results must carry as a warning (else None); both start with
    ``name``.

    A refusal caused by creases alone names ``atlas.allow_creases``: with it, the run goes on
    and its results are flagged (status completed_with_warnings), never presented as clean.
    """
    reason = refusal(points, check)
    if not reason:
        return None, None
    only_creases = bool(check.crease.any()) and refusal(points, CloudCheck(
        check.components, np.zeros_like(check.crease), check.nonmanifold)) is None
    if allow_creases and only_creases:
        return None, f"{name}: kept by atlas.allow_creases=true, but {reason}"
    if only_creases:
        reason += (" To run anyway with the results flagged as not trustworthy there, set "
                   "atlas.allow_creases=true.")
    return f"{name}: {reason}", None


#: coefficient of variation of the nearest-neighbour distance above which a cloud is irregular
#: for curvature on LME charts: quasi-uniform samples measure 0.004 (structured torus), 0.014
#: (Fibonacci sphere), 0.12 (connected_pipes); uniformly random ones 0.53-0.54 and pyvista's
#: sphere.ply 0.41
IRREGULAR_SPACING = 0.25


def spacing_variation(points: np.ndarray) -> float:
    """Standard deviation over mean of the nearest-neighbour distances of the (n, D) points
    (dimensionless)."""
    from scipy.spatial import cKDTree

    d = cKDTree(points).query(points, k=2)[0][:, 1]
    return float(d.std() / max(d.mean(), 1e-300))
