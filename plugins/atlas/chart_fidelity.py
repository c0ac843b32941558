"""Does a chart stay on its points? The test of a built chart against its own samples.

The chart test of :mod:`.chart_repair` judges the embedding ξ of a patch's control points;
it cannot see a chart map φ_κ that is wrong between them. A least-squares polynomial chart on
points sampled along lines a few spacings apart (a parametric mesh's grid) is underdetermined
across the lines: its tangent plane collapses (area element J → 0) or turns away, and the
curvatures there run to 10⁵ while the run looks sound (pyvista's ParametricEllipsoid(1.5, 1,
0.7): ∫K dA = 0.05·4π, Willmore energy 3·10⁵, every patch passing the embedding test).

Each Gauss point of a chart lies in a Delaunay triangle of ξ whose vertices are samples x_a
of the surface. On a smooth surface resolved by the samples the chart and the triangle's
affine map agree to first order: their area elements J/J_t and normals differ by O(κ ℓ)
(ℓ the edge length; measured on the sphere, torus and random sphere: J/J_t within
[0.84, 1.22], normals within 14°). A Gauss point where J/J_t leaves [1/2, 2] or the normals
are more than 45° apart is where the chart *departs* from its points. Only well-shaped
triangles are used (the shape quality of :func:`.partition.embedding_defects`), as a
sliver's own normal is unreliable.
"""
from __future__ import annotations

import numpy as np

#: a Gauss point departs where J/J_t is outside [1/MAX_AREA_RATIO, MAX_AREA_RATIO] ...
MAX_AREA_RATIO = 2.0
#: ... or where the chart's and the triangle's normals are more than 45° apart
MIN_NORMAL_COSINE = np.cos(np.pi / 4)
#: a chart is refused when its departing Gauss points carry more than this fraction of its
#: quadrature weight (w_g J ψ_κ). Sound charts measured 0 (sphere, torus, random sphere).
MAX_DEPARTED_WEIGHT = 1e-3
#: triangles of ξ with a shape quality (4√3 area / Σ edge², 1 for equilateral) below this
#: are slivers and are not judged
MIN_SHAPE_QUALITY = 0.2


def chart_departure(xi_nodes: np.ndarray, samples: np.ndarray, simplices: np.ndarray,
                    tangents: np.ndarray, weights: np.ndarray) -> dict[str, float]:
    """How far a surface chart (d = 2, D = 3) departs from its samples at its Gauss points.

    xi_nodes (n, 2), samples (n, 3): the chart's nodes and the points x_a they stand for;
    simplices (m, 3): the Delaunay triangle of ξ holding each Gauss point; tangents
    (m, 2, 3): ∂φ/∂ξ_α there; weights (m,): the Gauss weights w_g J ψ_κ.

    Returns ``departed_weight`` (fraction of the weight at departing points), the range of
    the area ratio J/J_t (``area_ratio_min``, ``area_ratio_max``) and ``normal_angle_max``
    (degrees) over the judged points. Other dimensions are not judged (zeros, ratio 1).
    """
    out = {"departed_weight": 0.0, "area_ratio_min": 1.0, "area_ratio_max": 1.0,
           "normal_angle_max": 0.0}
    if xi_nodes.shape[1] != 2 or samples.shape[1] != 3 or len(weights) == 0:
        return out
    S = simplices
    e1, e2 = xi_nodes[S[:, 1]] - xi_nodes[S[:, 0]], xi_nodes[S[:, 2]] - xi_nodes[S[:, 0]]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    l2 = np.sum(e1**2, 1) + np.sum(e2**2, 1) + np.sum((e2 - e1) ** 2, 1)
    good = 2.0 * np.sqrt(3.0) * np.abs(det) / np.maximum(l2, 1e-300) > MIN_SHAPE_QUALITY
    if not good.any():
        return out
    # the triangle's affine map ξ → x: F = [x1 − x0, x2 − x0] [e1, e2]⁻¹; its normal is
    # (x1 − x0) × (x2 − x0) / det and its area element |that|
    P0, P1, P2 = samples[S[good, 0]], samples[S[good, 1]], samples[S[good, 2]]
    n_t = np.cross(P1 - P0, P2 - P0) / det[good, None]
    J_t = np.linalg.norm(n_t, axis=1)
    T = tangents[good]
    n_g = np.cross(T[:, 0], T[:, 1])
    J_g = np.linalg.norm(n_g, axis=1)
    ratio = J_g / np.maximum(J_t, 1e-300)
    cosine = np.sum(n_g * n_t, axis=1) / np.maximum(J_g * J_t, 1e-300)
    departs = ((ratio < 1.0 / MAX_AREA_RATIO) | (ratio > MAX_AREA_RATIO)
               | (cosine < MIN_NORMAL_COSINE))
    total = float(np.sum(weights))
    out.update(
        departed_weight=float(np.sum(weights[good][departs]) / total) if total > 0 else 0.0,
        area_ratio_min=float(ratio.min()), area_ratio_max=float(ratio.max()),
        normal_angle_max=float(np.degrees(np.arccos(np.clip(cosine.min(), -1.0, 1.0)))))
    return out


def departs(departure: dict) -> bool:
    """The chart departs from its points on more than :data:`MAX_DEPARTED_WEIGHT` of its
    weight."""
    return departure.get("departed_weight", 0.0) > MAX_DEPARTED_WEIGHT


def departed_charts_message(points: np.ndarray, node_sets: list[np.ndarray],
                            departures: list[dict], weights: np.ndarray, refuse: bool) -> str:
    """One line: how many charts depart from their points, the share of the atlas's weight
    on them, the worst three (centroid of their control points, why), and what to try;
    ``refuse``: the refusal, else the warning of an allowed atlas."""
    bad = [k for k, dep in enumerate(departures) if departs(dep)]
    worst = sorted(bad, key=lambda k: departures[k]["departed_weight"], reverse=True)[:3]
    where = []
    for k in worst:
        dep = departures[k]
        c = points[node_sets[k]].mean(axis=0)
        where.append(
            f"chart {k} near ({', '.join(f'{v:.3g}' for v in c)}): on "
            f"{100 * dep['departed_weight']:.3g} % of its weight, area element ×"
            f"{dep['area_ratio_min']:.3g}..{dep['area_ratio_max']:.3g}, normals up to "
            f"{dep['normal_angle_max']:.0f}° off")
    share = float(np.sum(weights[bad]) / np.sum(weights)) if np.sum(weights) > 0 else 0.0
    head = (f"{len(bad)} of {len(departures)} charts depart from their points (the chart's "
            f"surface leaves the triangles of its samples: area element off by more than "
            f"×{MAX_AREA_RATIO:g} or normals by more than 45°); they carry {100 * share:.3g} % "
            "of the area; the worst: " + "; ".join(where))
    tips = ("a denser or more even sample (points along lines a few spacings apart, as on a "
            "parametric mesh's grid, leave a chart undetermined across them), wider charts "
            "(a smaller atlas.gamma_lme, e.g. 0.4), or atlas.chart_reproduction=linear")
    if refuse:
        return (head + ". Integrals, curvatures and energies would be wrong there, so none "
                f"are computed. Try {tips}; atlas.allow_failed_patches=true gives results "
                "flagged as unreliable.")
    return head + f". atlas.allow_failed_patches=true keeps them (results flagged); try {tips}."
