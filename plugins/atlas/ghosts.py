"""Ghost nodes beyond the boundary of a sampled surface (Paper 1 §4.1.2, thesis L1340).

Local max-ent basis functions become flat at the boundary of the convex hull of the nodes,
which locks the curvature there; as in subdivision finite elements, ghost nodes are added
beyond the free, supported and symmetry boundaries. Quadrature stays on the real surface:
the ghosts only enrich the node set. They are generated from the points alone: for each
boundary point, ``layers`` ghosts at distances k·h (k = 1…layers, h the local spacing) along
the outward conormal, lifted onto a local quadratic fit of the surface around the boundary
point, so the ghosts continue the surface smoothly (within O(h³/R²) of a sphere or cylinder
of radius R). At corners (largest angular gap > ``corner_gap_deg``) the corner region is
filled with the lattice i·h·n₁ + j·h·n₂ (0 ≤ i, j ≤ layers) spanned by the two edge conormals.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from pointatlas.errors import ConfigError

from .boundary import boundary_geometry, gap_directions

#: A boundary point is a corner when its largest angular gap exceeds this (edges ≈ 180°).
DEFAULT_CORNER_GAP_DEG = 225.0
#: Ghosts closer than this fraction of the local spacing to a point or another ghost are dropped.
MIN_SEPARATION = 0.5


def _in_plane_offsets(geo: dict, layers: int, corner_gap: float):
    """Ghost offsets in each boundary point's frame: (owner b, du, dv), spacing units."""
    owners, offsets = [], []
    out = gap_directions(geo)
    corner = geo["gap"] > corner_gap
    t1, t2 = geo["t1"], geo["t2"]
    for k in range(1, layers + 1):  # layer by layer, so nearer ghosts win de-duplication
        edge = np.flatnonzero(~corner)
        owners.append(edge)
        offsets.append(k * out[edge])
        for b in np.flatnonzero(corner):
            # outward normals of the two edges: n1 ⟂ t1 pointing away from t2, and vice versa
            n1 = np.array([t1[b, 1], -t1[b, 0]])
            n1 *= -np.sign(n1 @ t2[b]) or 1.0
            n2 = np.array([t2[b, 1], -t2[b, 0]])
            n2 *= -np.sign(n2 @ t1[b]) or 1.0
            for i in range(layers + 1):
                for j in range(layers + 1):
                    if max(i, j) == k:
                        owners.append(np.array([b]))
                        offsets.append((i * n1 + j * n2)[None, :])
    return np.concatenate(owners), np.concatenate(offsets)


def _thin(candidates: np.ndarray, h: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Keep candidates farther than MIN_SEPARATION·h from every point and earlier kept ghost."""
    d, _ = cKDTree(points).query(candidates)
    alive = d > MIN_SEPARATION * h
    tree = cKDTree(candidates)
    kept = np.zeros(len(candidates), dtype=bool)
    for g in np.flatnonzero(alive):
        near = tree.query_ball_point(candidates[g], MIN_SEPARATION * h[g])
        if not np.any(kept[near]):
            kept[g] = True
    return candidates[kept]


def ghost_points(points, mask, layers: int = 2, spacing: float | None = None,
                 n_neighbors: int = 12, corner_gap_deg: float = DEFAULT_CORNER_GAP_DEG
                 ) -> np.ndarray:
    """(G, 3) ghost nodes beyond the boundary of the sampled surface ``points`` (N, 3).

    ``mask`` (N,) flags the boundary points (:func:`pointatlas_atlas.boundary.boundary_mask`).
    Each boundary point p gets ghosts at in-plane distances k·h, k = 1…``layers``, along its
    outward conormal, with the height given by the quadratic least-squares fit of the surface
    in p's local frame (Paper 1 §4.1.2). ``spacing`` h: None = the local point spacing (mean
    nearest-neighbour distance around p), or a length. Ghosts within 0.5·h of a point or of
    another ghost are dropped, so all nodes stay distinct.
    """
    if not isinstance(layers, (int, np.integer)) or isinstance(layers, bool) or layers < 1:
        raise ConfigError(f"layers={layers!r} is invalid: must be an integer >= 1. "
                          "Use layers=2 (two rows of ghost nodes, as for LME with gamma ~ 0.8).")
    if spacing is not None and not (np.isfinite(spacing) and spacing > 0):
        raise ConfigError(f"spacing={spacing!r} is invalid: must be None (local spacing) or a "
                          "length > 0. Leave it None unless the spacing is known.")
    X = np.asarray(points, dtype=np.float64)
    mask = np.asarray(mask, dtype=bool)
    if not mask.any():
        return np.empty((0, 3))
    geo = boundary_geometry(X, mask, n_neighbors)
    h = geo["spacing"] if spacing is None else np.full(len(geo["idx"]), float(spacing))
    owner, off = _in_plane_offsets(geo, int(layers), np.deg2rad(corner_gap_deg))
    uv = off * h[owner, None]
    c = geo["coeffs"][owner]
    u, v = uv[:, 0], uv[:, 1]
    w = c[:, 0] * u + c[:, 1] * v + c[:, 2] * u * u + c[:, 3] * u * v + c[:, 4] * v * v
    local = np.column_stack([u, v, w])
    candidates = X[geo["idx"][owner]] + np.einsum("gk,gkj->gj", local, geo["frames"][owner])
    return _thin(candidates, h[owner], X)
