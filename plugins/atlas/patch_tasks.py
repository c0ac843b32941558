"""The atlas's per-patch work as pure functions of (shared data, one patch), for an executor.

Each patch's embedding (with its chart-test repair), chart and Gauss quadrature depends only
on the point array, the patch's control points and the partition of unity (thesis §3; the
thesis ran these loops with OpenMP). Written as module-level functions ``task(shared, item)``
they run unchanged in the run's process or as Dask tasks (:mod:`pointatlas.executor`): the
``shared`` dicts built here hold what every patch needs (sent once per map) and the items
what one patch needs. The results are the same bit for bit wherever they run.
"""
from __future__ import annotations

import numpy as np

from .chart import build_chart, chart_quadrature
from .chart_repair import embed_control_set
from .orientation import chart_frames


def patch_label(points: np.ndarray, J: np.ndarray, k: int | None = None) -> str:
    """How a task names its patch in an error: ``patch 17 (312 control points near (…))``."""
    c = points[J].mean(axis=0) if len(J) else np.zeros(points.shape[1])
    head = "patch" if k is None else f"patch {k}"
    return f"{head} ({len(J)} control points near ({', '.join(f'{v:.3g}' for v in c)}))"


def embed_task(shared: dict, J: np.ndarray):
    """The :class:`~.chart_repair.EmbeddingAttempt` kept for control set J."""
    return embed_control_set(shared["points"][J], shared["chain"], shared["max_stress"],
                             shared["max_distortion"])


def chart_task(shared: dict, item: tuple):
    """The chart of one patch: item = (J, ξ_J) (the embedding the chart test accepted)."""
    J, xi = item
    return build_chart(shared["points"], J, None, shared["make_lme"],
                       shared["least_squares_fit"], xi=xi)


def patch_values(pu, n_markers: int, members: np.ndarray, X: np.ndarray) -> np.ndarray:
    """ψ_κ(X) = Σ_{A ∈ I_κ} w_A(X): the patch's share of the Shepard partition of unity."""
    w = pu.evaluate(X, order=0)
    mask = np.zeros(n_markers, dtype=np.float64)
    mask[members] = 1.0
    rows = np.repeat(np.arange(w.n_points), np.diff(w.indptr))
    return np.bincount(rows, weights=w.values * mask[w.indices], minlength=len(X))


def quadrature_task(shared: dict, item: tuple):
    """(Gauss points, orientation frames) of one chart: item = (chart, ψ_κ at its nodes,
    marker indices I_κ, real flags of its nodes or None, the nodes whose frames orient the
    atlas (:func:`.orientation.frame_masks`))."""
    chart, support, members, real, frame_mask = item
    pu, n_markers = shared["pu"], shared["n_markers"]
    q = chart_quadrature(chart, support, lambda X: patch_values(pu, n_markers, members, X),
                         shared["order"], shared["tol_pu"], shared["need_second"],
                         real=real, keep_basis=shared["keep_basis"])
    return q, chart_frames(chart, frame_mask)
