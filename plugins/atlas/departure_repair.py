"""Split a chart that departs from its points and build its halves instead.

The chart test of :mod:`.chart_repair` judges a patch's embedding; :mod:`.chart_fidelity`
judges the built chart map at its Gauss points. A patch can pass the first and fail the
second: on the Stanford bunny (pymeshlab's sample, 28 088 points, default atlas, PCA
charts) one of 190 charts (76 + 77 markers, depth 0) turns its normals 58.7° away from its
samples' triangles on 0.10 % of its weight, just over
:data:`.chart_fidelity.MAX_DEPARTED_WEIGHT`. The cure of the partition step applies here
too: bisect the patch (METIS on its marker graph, as :func:`.partition.refine_partition`)
and build a chart on each half. There, the halves pass the chart test, depart on 0 % of
their weight (normals within 35° and 20°) and carry 0.002556 + 0.002516 of the area where
the chart carried 0.005078.

Splitting patch κ into κ', κ'' changes nothing else: the Shepard weights of its markers
are aggregated into ψ_κ' + ψ_κ'' = ψ_κ, so every other chart's ψ, control set, chart and
Gauss points stay as they were and only the halves are built. The orientation frames of the
other charts lose at most the control points no chart but the split one used; those are set
to NaN (:func:`.orientation.frame_masks`), so the atlas equals one partitioned that way.
"""
from __future__ import annotations

import numpy as np

from .chart_fidelity import departs
from .orientation import frame_masks
from .partition import MIN_PATCH_MARKERS, bisect_patch


def split_departed_charts(atlas, frames: list, real, need_second: bool, keep_basis: bool,
                          progress) -> int:
    """Replace every departing chart (after the atlas's quadrature) by the charts of its
    halves, while the halves pass the chart test and depart on at most half its area, up to
    ``max_refinement_depth``; updates labels_, accepted_, patch_depth_, patch_embedder_,
    support_, charts_, quadrature_ and ``frames`` in place. Returns the number of charts
    split (also ``departed_splits_``).

    A split is kept only if every half passes the chart test; otherwise the chart stays and
    is refused or flagged as departing by the caller. Charts fitted once for the whole atlas
    (least_squares_scope='global') are not split (the fit couples all charts).
    """
    s = atlas.settings
    atlas.departed_splits_ = 0
    if atlas.interpolates() and s.least_squares_scope != "chart":
        return 0
    splittable = set(range(len(atlas.charts_)))
    for _ in range(s.max_refinement_depth):
        candidates = [k for k in sorted(splittable)
                      if departs(atlas.quadrature_[k].departure or {})
                      and atlas.patch_depth_[k] < s.max_refinement_depth
                      and np.count_nonzero(atlas.labels_ == k) >= 2 * MIN_PATCH_MARKERS]
        if not candidates:
            break
        splits = {k: bisect_patch(atlas.adjacency_, np.flatnonzero(atlas.labels_ == k))
                  for k in candidates}
        atlas._prefetch_embeddings([h for halves in splits.values() for h in halves])
        splits = {k: halves for k, halves in splits.items()
                  if len(halves) > 1 and all(atlas._acceptable(h) for h in halves)}
        if not splits:
            break
        before = {k: departed_area(atlas.quadrature_[k]) for k in splits}
        groups = _relabel(atlas, splits, progress)
        new_ids = [lab for labs in groups.values() for lab in labs]
        done = atlas._quadrature_of(new_ids, real, need_second, keep_basis, progress,
                                    desc="quadrature (split charts)")
        for k, (q, f) in zip(new_ids, done):
            if k < len(atlas.quadrature_):
                atlas.quadrature_[k], frames[k] = q, f
            else:
                atlas.quadrature_.append(q)
                frames.append(f)
        masks = frame_masks(atlas)
        for k in set(range(len(frames))) - set(new_ids):
            frames[k][~masks[k]] = np.nan      # control points only the split chart used
        atlas.departed_splits_ += len(splits)
        # split again only where splitting helped: the halves depart on at most half the
        # area the chart did (a chart map that is wrong at any size, e.g. an ill-posed fit,
        # is not split down to the depth limit)
        splittable = {lab for k, labs in groups.items()
                      if sum(departed_area(atlas.quadrature_[j]) for j in labs) <= before[k] / 2
                      for lab in labs}
    return atlas.departed_splits_


def departed_area(q) -> float:
    """The quadrature weight (area share) at which chart quadrature ``q`` departs."""
    return float((q.departure or {}).get("departed_weight", 0.0) * q.weights.sum())


def _relabel(atlas, splits: dict[int, list[np.ndarray]], progress) -> dict[int, list[int]]:
    """Give each split patch's first half its label and the others new ones; build their
    charts. Returns, per split patch, the labels of its halves (whose charts are new)."""
    L = len(atlas.charts_)
    groups: dict[int, list[int]] = {k: [] for k in splits}
    depth, accepted = list(atlas.patch_depth_), list(atlas.accepted_)
    for k, halves in splits.items():
        for i, members in enumerate(halves):
            lab = k if i == 0 else L
            L += i > 0
            atlas.labels_[members] = lab
            groups[k].append(lab)
            if lab == k:
                depth[k], accepted[k] = depth[k] + 1, True
            else:
                depth.append(depth[k])
                accepted.append(True)
    atlas.patch_depth_ = np.array(depth, dtype=np.int64)
    atlas.accepted_ = np.array(accepted, dtype=bool)
    new_ids = [lab for labs in groups.values() for lab in labs]
    atlas.support_ += [None] * (L - len(atlas.support_))
    charts = atlas._charts_of(new_ids, progress, desc="charts (split)")
    atlas.charts_ += [None] * (L - len(atlas.charts_))
    for lab, chart in zip(new_ids, charts):
        atlas.charts_[lab] = chart
    embedders = list(atlas.patch_embedder_) + [""] * (L - len(atlas.patch_embedder_))
    for lab, attempt in zip(new_ids, atlas._patch_attempts(new_ids)):
        embedders[lab] = "none" if attempt is None else attempt.embedder
    atlas.patch_embedder_ = np.array(embedders)
    return groups
