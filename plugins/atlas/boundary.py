"""Boundary of a sampled surface: which points lie on it, its curves, its outward conormals.

Paper 1 §4.1.2 (thesis L1330–1345): local max-ent basis functions become flat at the
boundary of the convex hull of the nodes, so ghost nodes are added beyond free, supported and
symmetry boundaries; for that, and to impose boundary conditions on the boundary curves
(Paper 1 §4.1.1, Gauss points on the boundary curves), the boundary must be found from the
points alone. The method is geometric: a point is on the boundary when, seen in its local
tangent plane (local PCA, as the tangent-plane estimate of thesis §3.2 without weights), its
k nearest neighbours leave an angular gap wider than a threshold (about 180° on an edge, 270°
at a right corner, at most ~90° inside a quasi-uniform set).

Pure functions on (N, 3) arrays of coordinates (length units of the points).
"""
from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, minimum_spanning_tree, shortest_path
from scipy.spatial import cKDTree

from pointatlas.errors import InputError

#: Default gap threshold: edges give ≈180° (≈150° on a hole of radius 4h), right corners 270°,
#: interior points of jittered or Poisson-disc-like sets stay below ≈100° (measured on the
#: four shell sources, n = 300–1500). Independent uniform random points have true holes and
#: give false positives.
DEFAULT_MIN_GAP_DEG = 115.0


def _check_points(points, n_neighbors: int) -> np.ndarray:
    X = np.asarray(points, dtype=np.float64)
    if X.ndim != 2 or X.shape[1] != 3:
        raise InputError(f"points must have shape (N, 3); got {X.shape}.")
    if X.shape[0] <= n_neighbors:
        raise InputError(
            f"need more than n_neighbors={n_neighbors} points, got {X.shape[0]}; "
            "pass fewer neighbours or more points.")
    return X


def nearest_neighbors(points: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Indices (N, k) and distances (N, k) of each point's k nearest other points."""
    dist, idx = cKDTree(points).query(points, k=k + 1)
    return idx[:, 1:], dist[:, 1:]


def local_spacing(points: np.ndarray, neighbors: np.ndarray) -> np.ndarray:
    """Local point spacing h_i: nearest-neighbour distance averaged over i's neighbourhood."""
    nn = np.linalg.norm(points[neighbors[:, 0]] - points, axis=1)
    return (nn + nn[neighbors].sum(axis=1)) / (neighbors.shape[1] + 1)


def tangent_frames(points: np.ndarray, neighbors: np.ndarray) -> np.ndarray:
    """Orthonormal frames (N, 3, 3), rows (e1, e2, n): local PCA of each point and its
    neighbours (e1, e2 span the least-squares tangent plane, n is its normal)."""
    nb = np.concatenate([points[:, None, :], points[neighbors]], axis=1)
    centred = nb - nb.mean(axis=1, keepdims=True)
    cov = np.einsum("nki,nkj->nij", centred, centred)
    _, vecs = np.linalg.eigh(cov)  # ascending eigenvalues: columns (n, e2, e1)
    return np.stack([vecs[:, :, 2], vecs[:, :, 1], vecs[:, :, 0]], axis=1)


def angular_gaps(points: np.ndarray, neighbors: np.ndarray, frames: np.ndarray):
    """Largest angular gap between neighbour directions in each tangent plane.

    Returns ``(gap, first, second)``: the gap (radians, in (0, 2π]) and, for each point, the
    columns of ``neighbors`` bounding it (going counter-clockwise from ``first`` across the
    gap reaches ``second``).
    """
    offsets = points[neighbors] - points[:, None, :]
    u = np.einsum("nkj,nj->nk", offsets, frames[:, 0])
    v = np.einsum("nkj,nj->nk", offsets, frames[:, 1])
    ang = np.arctan2(v, u)
    order = np.argsort(ang, axis=1)
    s = np.take_along_axis(ang, order, axis=1)
    gaps = np.diff(np.concatenate([s, s[:, :1] + 2 * np.pi], axis=1), axis=1)
    j = np.argmax(gaps, axis=1)
    rows = np.arange(len(points))
    k = neighbors.shape[1]
    return gaps[rows, j], order[rows, j], order[rows, (j + 1) % k]


def boundary_mask(points, n_neighbors: int = 12, min_gap_deg: float = DEFAULT_MIN_GAP_DEG):
    """(N,) bool: points on the boundary of the sampled surface (Paper 1 §4.1.2).

    A point is flagged when its ``n_neighbors`` nearest neighbours, projected to its local
    PCA tangent plane, leave an angular gap larger than ``min_gap_deg`` degrees. A closed
    surface (sphere, torus) gives no boundary point.
    """
    X = _check_points(points, n_neighbors)
    nb, _ = nearest_neighbors(X, n_neighbors)
    gap, _, _ = angular_gaps(X, nb, tangent_frames(X, nb))
    return gap > np.deg2rad(min_gap_deg)


def _link_length(points: np.ndarray, link_factor: float) -> float:
    nn = cKDTree(points).query(points, k=2)[0][:, 1]
    return link_factor * float(np.median(nn))


def _order_component(P: np.ndarray, graph) -> np.ndarray:
    """Order the points of one connected component along the curve: the longest path of
    its minimum spanning tree, with stray points inserted after their nearest path point."""
    tree = minimum_spanning_tree(graph)
    tree = tree + tree.T
    d0 = shortest_path(tree, directed=False, indices=0)
    a = int(np.argmax(np.where(np.isfinite(d0), d0, -1)))
    da, pred = shortest_path(tree, directed=False, indices=a, return_predecessors=True)
    b = int(np.argmax(np.where(np.isfinite(da), da, -1)))
    path = [b]
    while path[-1] != a:
        path.append(int(pred[path[-1]]))
    path = np.array(path[::-1])
    rest = np.setdiff1d(np.arange(len(P)), path)
    if rest.size == 0:
        return path
    dist, pos = cKDTree(P[path]).query(P[rest])
    keys = np.concatenate([np.arange(len(path), dtype=np.float64), pos + 0.5 + 1e-9 * dist])
    return np.concatenate([path, rest])[np.argsort(keys, kind="stable")]


def boundary_curves(points, mask, link_factor: float = 3.0) -> list[np.ndarray]:
    """The boundary points split into connected curves, each ordered along the curve.

    Boundary points closer than ``link_factor`` × (median nearest-neighbour distance of all
    points) are linked; each connected component is one curve, ordered along the longest
    path of its minimum spanning tree. Returns index arrays into ``points`` (largest curve
    first). Use :func:`is_closed_curve` to tell closed curves from open ones.
    """
    X = np.asarray(points, dtype=np.float64)
    idx = np.flatnonzero(np.asarray(mask, dtype=bool))
    if idx.size == 0:
        return []
    if idx.size == 1:
        return [idx]
    P = X[idx]
    r = _link_length(X, link_factor)
    pairs = cKDTree(P).query_pairs(r=r, output_type="ndarray")
    w = np.linalg.norm(P[pairs[:, 0]] - P[pairs[:, 1]], axis=1) + 1e-300
    n = len(P)
    graph = coo_matrix((w, (pairs[:, 0], pairs[:, 1])), shape=(n, n)).tocsr()
    n_comp, labels = connected_components(graph, directed=False)
    curves = []
    for c in range(n_comp):
        members = np.flatnonzero(labels == c)
        sub = graph[members][:, members]
        curves.append(idx[members[_order_component(P[members], sub)]])
    curves.sort(key=len, reverse=True)
    return curves


def is_closed_curve(points, curve, link_factor: float = 3.0) -> bool:
    """True when an ordered boundary curve closes on itself: its two ends are linked
    (closer than ``link_factor`` × median nearest-neighbour distance) and it has ≥ 3 points."""
    X = np.asarray(points, dtype=np.float64)
    if len(curve) < 3:
        return False
    gap = np.linalg.norm(X[curve[0]] - X[curve[-1]])
    return bool(gap <= _link_length(X, link_factor))


def fit_quadratic(local: np.ndarray) -> np.ndarray:
    """Least-squares coefficients c of w = c1 u + c2 v + c3 u² + c4 uv + c5 v² through the
    origin, from local coordinates (k, 3) = (u, v, w) of neighbours (k ≥ 5)."""
    u, v, w = local.T
    A = np.column_stack([u, v, u * u, u * v, v * v])
    scale = np.sqrt(np.mean(u * u + v * v)) or 1.0
    S = np.array([scale, scale, scale**2, scale**2, scale**2])
    c, *_ = np.linalg.lstsq(A / S, w, rcond=None)
    return c / S


def boundary_geometry(points, mask, n_neighbors: int = 12):
    """Per boundary point: frame, quadratic fit and the edge directions bounding the gap.

    Returns a dict of arrays over ``idx = flatnonzero(mask)``: ``idx``, ``frames`` (B, 3, 3),
    ``coeffs`` (B, 5) of :func:`fit_quadratic` in that frame, ``t1``, ``t2`` (B, 2) unit
    in-plane directions to the two neighbours bounding the largest gap, ``gap`` (B,) radians,
    ``spacing`` (B,) local spacing. Used for conormals and ghost nodes.
    """
    X = _check_points(points, n_neighbors)
    nb, _ = nearest_neighbors(X, n_neighbors)
    frames = tangent_frames(X, nb)
    gap, first, second = angular_gaps(X, nb, frames)
    h = local_spacing(X, nb)
    idx = np.flatnonzero(np.asarray(mask, dtype=bool))
    coeffs = np.empty((idx.size, 5))
    t1 = np.empty((idx.size, 2))
    t2 = np.empty((idx.size, 2))
    for b, i in enumerate(idx):
        F = frames[i]
        local = (X[nb[i]] - X[i]) @ F.T
        coeffs[b] = fit_quadratic(local)
        for t, col in ((t1, first[i]), (t2, second[i])):
            t[b] = local[col, :2] / np.linalg.norm(local[col, :2])
    return {"idx": idx, "frames": frames[idx], "coeffs": coeffs, "t1": t1, "t2": t2,
            "gap": gap[idx], "spacing": h[idx]}


def lift(coeffs: np.ndarray, d: np.ndarray) -> np.ndarray:
    """In-plane directions d (B, 2) lifted to tangent vectors (B, 3) of the fitted surface
    at the origin of the frame (unnormalised: (d1, d2, c1 d1 + c2 d2))."""
    return np.column_stack([d, coeffs[:, 0] * d[:, 0] + coeffs[:, 1] * d[:, 1]])


def gap_directions(geo) -> np.ndarray:
    """Unit in-plane (B, 2) outward directions: perpendicular to the chord between the two
    gap-bounding neighbours, pointing into the gap (the angle bisector at a corner)."""
    t1, t2 = geo["t1"], geo["t2"]
    chord = t2 - t1
    perp = np.column_stack([chord[:, 1], -chord[:, 0]])
    # the gap opens counter-clockwise from t1 to t2: its bisector
    half = 0.5 * geo["gap"]
    c, s = np.cos(half), np.sin(half)
    bis = np.column_stack([c * t1[:, 0] - s * t1[:, 1], s * t1[:, 0] + c * t1[:, 1]])
    perp *= np.where(np.einsum("ij,ij->i", perp, bis) < 0, -1.0, 1.0)[:, None]
    norm = np.linalg.norm(perp, axis=1, keepdims=True)
    return np.where(norm > 1e-12, perp / np.where(norm > 0, norm, 1.0), bis)


def outward_conormals(points, mask, n_neighbors: int = 12) -> np.ndarray:
    """(N, 3) unit outward conormals at boundary points, zero rows elsewhere.

    The conormal is tangent to the surface (the local quadratic fit at the point), normal to
    the boundary (perpendicular to the chord between the point's two boundary neighbours,
    which bound the largest angular gap) and points out of the surface, into the gap.
    At a corner it is the bisector of the two edge conormals.
    """
    X = _check_points(points, n_neighbors)
    out = np.zeros_like(X)
    if not np.any(mask):
        return out
    geo = boundary_geometry(X, mask, n_neighbors)
    c = geo["coeffs"]
    approx = lift(c, gap_directions(geo))
    normal = np.column_stack([-c[:, 0], -c[:, 1], np.ones(len(c))])
    tangent = np.cross(lift(c, geo["t2"] - geo["t1"]), normal)
    tangent *= np.where(np.einsum("ij,ij->i", tangent, approx) < 0, -1.0, 1.0)[:, None]
    bad = np.linalg.norm(tangent, axis=1) < 1e-12 * np.linalg.norm(approx, axis=1)
    tangent[bad] = approx[bad]
    world = np.einsum("bk,bkj->bj", tangent, geo["frames"])
    out[geo["idx"]] = world / np.linalg.norm(world, axis=1, keepdims=True)
    return out


def curve_segments(points, curves, max_length: float) -> np.ndarray:
    """(s, 2) index pairs of neighbouring points along the ordered curves, the closing pair
    of closed curves included; pairs longer than ``max_length`` (jumps in the ordering of a
    branched curve) are left out."""
    X = np.asarray(points, dtype=np.float64)
    pairs = []
    for curve in curves:
        c = np.asarray(curve, dtype=np.int64)
        if len(c) < 2:
            continue
        p = np.column_stack([c[:-1], c[1:]])
        if len(c) >= 3 and np.linalg.norm(X[c[0]] - X[c[-1]]) <= max_length:
            p = np.vstack([p, [c[-1], c[0]]])
        pairs.append(p)
    if not pairs:
        return np.zeros((0, 2), dtype=np.int64)
    p = np.vstack(pairs)
    return p[np.linalg.norm(X[p[:, 0]] - X[p[:, 1]], axis=1) <= max_length]
