"""The atlas of a point-set manifold: patches, coarse partition of unity, charts, quadrature.

Thesis §3 (L125–360) and Paper 2 §3: markers Q are partitioned into patches I_κ (METIS,
recursive re-partition of unacceptable patches); a Shepard PU w_A over all markers is
aggregated by patch, ψ_κ = Σ_{A∈I_κ} w_A; each patch gets a chart φ_κ on the embedded
control points J_κ ⊃ {a : ψ_κ(P_a) > tol}; integrals are ∫_M f ≈ Σ_κ Σ_g w_g J_κ ψ_κ f.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from itertools import chain
from typing import Callable, Optional

import numpy as np
from scipy.sparse import csr_matrix
from scipy.spatial import cKDTree

from pointatlas.errors import InputError
from pointatlas.executor import current_executor

from . import differential_geometry as dg, memory_estimate as mem, patch_tasks
from .settings import GEOMETRY_MARKERS_PER_PATCH, AtlasSettings
from .chart import Chart, ChartQuadrature
from .quadrature import simplex_rule
from .partition import (is_connected, label_members, partition_markers, patch_share,
                        refine_partition, share_at)
from .chart_coverage import MAX_EDGE_PU, atlas_edge_message, check_chart_edges
from .chart_fidelity import departed_charts_message, departs
from .chart_repair import (AtlasError, EmbeddingAttempt, Fresh, embed_control_set,
                           failed_patches_message, repair_embedders)


@dataclass
class QuadraturePoints:
    """All quadrature points of the atlas (concatenated over charts)."""

    chart: np.ndarray         # (m,) chart index
    weights: np.ndarray       # (m,) w_g J ψ_κ
    positions: np.ndarray     # (m, D)
    tangents: np.ndarray      # (m, d, D)
    geometry: dict = field(default_factory=dict)  # dg.Geometry: metric, J, normal, H, K ...


class Atlas:
    """Charts glued by a coarse Shepard partition of unity; ``build`` then ``integrate``."""

    def __init__(self, settings: AtlasSettings, make_embedder: Callable[[], object],
                 make_lme: Callable[[], object], make_pu: Callable[[], object]):
        self.settings = settings
        self.make_embedder = make_embedder
        self.make_lme = make_lme
        self.make_pu = make_pu

    # -- partition of unity ----------------------------------------------------------
    def patch_pu(self, X: np.ndarray, labels: Optional[np.ndarray] = None) -> csr_matrix:
        """ψ_κ at ambient points X as an (m, L) sparse matrix (rows sum to 1 where defined)."""
        labels = self.labels_ if labels is None else labels
        w = self.pu_.evaluate(X, order=0)
        W = w.to_csr(self.markers_.shape[0])
        L = int(labels.max()) + 1
        agg = csr_matrix((np.ones(labels.size), (np.arange(labels.size), labels)),
                         shape=(labels.size, L))
        return (W @ agg).tocsr()

    # -- construction ----------------------------------------------------------------
    def _control_set(self, members: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """J_κ and ψ_κ at its points: points where ψ_κ > tol_pu, grown by the margin."""
        key = members.tobytes()
        if key in self._control_sets:
            return self._control_sets[key]
        rows, psi = patch_share(self.W_points_, members)  # O(patch), not O(N)
        core = rows[psi > self.settings.tol_pu]
        if core.size == 0:
            core = np.unique(self.point_tree_.query(self.markers_[members], k=1)[1])
        indptr, indices = self._margin_neighbors()
        starts, stops = indptr[core], indptr[core + 1]
        counts = stops - starts
        flat = np.repeat(starts - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())
        J = np.unique(np.concatenate([core, indices[flat]]))
        self._control_sets[key] = (J, share_at(rows, psi, J))
        return self._control_sets[key]

    def _margin_neighbors(self) -> tuple[np.ndarray, np.ndarray]:
        """Points within chart_margin·h of every point, as CSR (indptr, indices); built once."""
        if self._margin_csr is None:
            r = self.settings.margin_for(self.chart_dim_) * self.h_points_
            near = self.point_tree_.query_ball_point(self.points_, r)
            counts = np.fromiter((len(n) for n in near), dtype=np.int64, count=len(near))
            indptr = np.concatenate([[0], np.cumsum(counts)])
            indices = np.fromiter(chain.from_iterable(near), dtype=np.int64,
                                  count=int(indptr[-1]))
            self._margin_csr = (indptr, indices)
        return self._margin_csr

    def _embedding(self, J: np.ndarray) -> np.ndarray:
        """Ξ_κ = R_κ(P_J) by the embedder the chart test accepted (the least bad one if none
        did), computed once per control set: the acceptance test's embedding is the chart's."""
        return self._embedding_attempt(J).xi

    def _embedding_attempt(self, J: np.ndarray) -> EmbeddingAttempt:
        """Embed P_J with the configured embedder and, while the chart test fails, with the
        geodesic ones (:func:`chart_repair.repair_embedders`); cached per control set."""
        key = J.tobytes()
        if key not in self._embeddings:
            s = self.settings
            self._embeddings[key] = embed_control_set(self.points_[J], self._repair_chain,
                                                      s.max_stress, s.max_distortion)
        return self._embeddings[key]

    def _prefetch_embeddings(self, patches: list[np.ndarray]) -> None:
        """On a distributed executor, embed the control sets of ``patches`` (one depth of
        the refinement) in one map; :meth:`_acceptable` then finds them cached."""
        executor = current_executor()
        if not executor.distributed:
            return
        todo: dict[bytes, np.ndarray] = {}
        for members in patches:
            if is_connected(self.adjacency_, members):
                J, _ = self._control_set(members)
                if J.tobytes() not in self._embeddings:
                    todo.setdefault(J.tobytes(), J)
        Js = list(todo.values())
        s = self.settings
        shared = {"points": self.points_, "chain": self._repair_chain,
                  "max_stress": s.max_stress, "max_distortion": s.max_distortion}
        attempts = executor.map(patch_tasks.embed_task, Js, shared=shared,
                                desc="patch embeddings", costs=[len(J) ** 2 for J in Js],
                                labels=[patch_tasks.patch_label(self.points_, J) for J in Js])
        for J, attempt in zip(Js, attempts):
            self._embeddings[J.tobytes()] = attempt

    def _acceptable(self, members: np.ndarray) -> bool:
        if not is_connected(self.adjacency_, members):
            return False
        J, _ = self._control_set(members)
        attempt = self._embedding_attempt(J)
        self.defects_[tuple(members[:3])] = attempt.defects
        return attempt.passed

    def estimated_bytes(self, n_points: int, n_markers: int, ambient_dim: int, chart_dim: int,
                        keep_basis: bool = False) -> int:
        """Bytes the built atlas will hold (:func:`memory_estimate.estimate_atlas_bytes` with
        the supports of these settings' LME charts and Shepard partition of unity)."""
        s = self.settings
        return mem.estimate_atlas_bytes(
            n_points, ambient_dim, chart_dim, mem.support_size(chart_dim, s.gamma_lme, s.tol_lme),
            pu_support_size=mem.support_size(chart_dim, s.gamma_pu, s.tol_pu),
            quadrature_order=s.quadrature_order, n_markers=n_markers,
            margin=s.margin_for(chart_dim), keep_basis=keep_basis)

    def partition(self, points: np.ndarray, markers: Optional[np.ndarray] = None, *,
                  keep_basis: bool = False, extra_bytes: int = 0,
                  extra_what: str = "", extra_fix: str = "") -> np.ndarray:
        """Partition the markers (default: the points) and fit the PU. Returns labels (M,).

        First refuses (InputError) an atlas whose estimated memory does not fit the memory
        available; ``keep_basis``: the quadrature will keep the basis functions (counted).
        """
        s = self.settings
        s.check()
        P = np.asarray(points, dtype=np.float64)
        Q = P if markers is None else np.asarray(markers, dtype=np.float64)
        if P.ndim != 2 or Q.ndim != 2 or Q.shape[1] != P.shape[1]:
            raise InputError(f"points {P.shape} and markers {Q.shape} must be (n, D) arrays "
                             "with the same D.")
        # the chart dimension d, for d-dependent defaults (the embedders' n_components)
        self.chart_dim_ = int(getattr(self.make_embedder(), "n_components", 2))
        # refuse, before any work, an atlas that cannot fit in memory (one line, with fix)
        mem.check_atlas_memory(self, P.shape[0], Q.shape[0], P.shape[1], keep_basis,
                               extra_bytes, extra_what, extra_fix)
        self.points_, self.markers_ = P, Q
        self.point_tree_ = cKDTree(P)
        self._control_sets, self._embeddings, self._margin_csr = {}, {}, None
        self.h_points_ = float(np.median(self.point_tree_.query(P, k=2)[0][:, 1]))
        self.pu_ = self.make_pu().fit(Q)
        self.W_points_ = self.pu_.evaluate(P, order=0).to_csr(Q.shape[0]).tocsc()
        per_patch = s.markers_per_patch or GEOMETRY_MARKERS_PER_PATCH
        n_parts = s.n_patches or max(1, int(round(Q.shape[0] / per_patch)))
        labels, self.adjacency_ = partition_markers(Q, n_parts, s.graph_neighbors)
        self.initial_n_patches_ = int(labels.max()) + 1
        self.defects_ = {}
        self._repair_chain = repair_embedders(Fresh(self.make_embedder()), self.chart_dim_)
        self.repair_embedders_ = [name for name, _ in self._repair_chain]
        self.labels_, self.accepted_, self.patch_depth_ = refine_partition(
            labels, self.adjacency_, self._acceptable, max_depth=s.max_refinement_depth,
            prefetch=self._prefetch_embeddings)
        attempts = self._patch_attempts(range(self.accepted_.size))
        self.patch_embedder_ = np.array(["none" if a is None else a.embedder for a in attempts])
        if not self.accepted_.all() and not s.allow_failed_patches:
            raise AtlasError(self._failed_patches_message(refuse=True))
        return self.labels_

    def _patch_attempts(self, patches) -> list[Optional[EmbeddingAttempt]]:
        """The embedding kept for each final patch (None: disconnected, never embedded)."""
        return [self._embeddings.get(self._control_set(members)[0].tobytes())
                for members in label_members(self.labels_, patches)]

    def failed_point_fraction(self) -> float:
        """Σ_a Σ_{κ failed} ψ_κ(P_a) / N: the share of the points, by the partition of unity,
        on patches that fail the chart test (after :meth:`partition`)."""
        failed = ~self.accepted_[self.labels_]          # per marker
        psi = self.W_points_ @ failed.astype(np.float64)
        return float(np.mean(psi))

    def _failed_patches_message(self, refuse: bool) -> str:
        s = self.settings
        return failed_patches_message(
            self.markers_, self.labels_, self.accepted_,
            self._patch_attempts(range(self.accepted_.size)), s.max_stress,
            s.max_distortion, self.repair_embedders_, self.failed_point_fraction(),
            s.max_refinement_depth, refuse=refuse)

    def refinement_warning(self) -> Optional[str]:
        """Why the atlas may be wrong, if patches still fail the chart test after the repair
        of :meth:`partition` (only with ``allow_failed_patches``: else it refused); else None."""
        kept = list(getattr(self, "kept_defects_", []))  # e.g. creases, atlas.allow_creases
        if not self.accepted_.all():
            kept.append(self._failed_patches_message(refuse=False))
        if hasattr(self, "quadrature_") and not self.charts_faithful().all():
            kept.append(self._departed_charts_message(refuse=False))
        if hasattr(self, "edge_pu_") and not self.charts_covered().all():
            kept.append(atlas_edge_message(self, refuse=False))
        return "; ".join(kept) or None

    def charts_faithful(self) -> np.ndarray:
        """(L,) bool: the chart stays on its points at its Gauss points
        (:mod:`.chart_fidelity`; after :meth:`build_quadrature`)."""
        return np.array([not departs(q.departure or {}) for q in self.quadrature_], bool)

    def charts_covered(self) -> np.ndarray:
        """(L,) bool: ψ_κ stays off the rim of the chart's domain (:mod:`.chart_coverage`;
        after :meth:`build_quadrature`)."""
        return self.edge_pu_ <= MAX_EDGE_PU

    def _departed_charts_message(self, refuse: bool) -> str:
        return departed_charts_message(
            self.points_, [c.node_index for c in self.charts_],
            [q.departure or {} for q in self.quadrature_],
            np.array([q.weights.sum() for q in self.quadrature_]), refuse)

    def interpolates(self) -> bool:
        """Whether the control points are fitted so that the charts interpolate the points
        (``least_squares_fit``, Paper 2 App. B). Only linear (LME) charts are: the LME basis
        at its nodes is a diagonally dominant smoothing, which the fit undoes. A polynomial
        chart (``chart_reproduction`` quadratic to quartic) already passes within O(σ^{k+1})
        of its points, and its basis at the nodes is not diagonally dominant: the fit
        amplifies the noise of ξ instead (quartic charts on pyvista's ParametricEllipsoid:
        control points up to 858 spacings off their points, 7 of 41 charts departing)."""
        s = self.settings
        return bool(s.least_squares_fit) and s.chart_reproduction == "linear"

    def build_charts(self, progress=lambda it, **kw: it) -> list[Chart]:
        """One chart per patch (after :meth:`partition`). With least_squares_fit, the control
        points interpolate the points chart by chart (least_squares_scope='chart') or are fitted
        once for the whole atlas (least_squares_scope='global', Paper 2 App. B)."""
        L = int(self.labels_.max()) + 1
        self.support_ = [None] * L
        self.charts_ = self._charts_of(range(L), progress)
        if self.interpolates() and self.settings.least_squares_scope != "chart":
            from .surface_fit import fit_control_points

            self.control_point_fit_ = fit_control_points(self, self.points_)
        return self.charts_

    def _charts_of(self, patches, progress, desc: str = "charts") -> list[Chart]:
        """The charts of ``patches`` (indices into the labels), each on the embedding the
        chart test accepted (chart_repair); sets their ``support_`` entries."""
        sets = [self._control_set(members) for members in label_members(self.labels_, patches)]
        for k, (_, psi) in zip(patches, sets):
            self.support_[k] = psi
        shared = {"points": self.points_, "make_lme": Fresh(self.make_lme()),
                  "least_squares_fit": self.interpolates()
                  and self.settings.least_squares_scope == "chart"}
        return self._map_patches(patch_tasks.chart_task,
                                 [(J, self._embedding(J)) for J, _ in sets], shared, desc,
                                 [J for J, _ in sets], progress)

    def _quadrature_of(self, patches, real, need_second: bool, keep_basis: bool, progress,
                       desc: str = "quadrature") -> list:
        """(Gauss points, orientation frames) of the charts ``patches``; the frames are patch
        work too (a distributed client then never evaluates the charts itself)."""
        from .orientation import frame_masks

        s = self.settings
        shared = {"pu": self.pu_, "n_markers": self.markers_.shape[0],
                  "order": s.quadrature_order, "tol_pu": s.tol_pu,
                  "need_second": need_second, "keep_basis": keep_basis}
        masks = frame_masks(self)
        charts, members = [self.charts_[k] for k in patches], label_members(self.labels_, patches)
        real = None if real is None else np.asarray(real, bool)
        items = [(c, self.support_[k], J, None if real is None else real[c.node_index], masks[k])
                 for k, c, J in zip(patches, charts, members)]
        return self._map_patches(patch_tasks.quadrature_task, items, shared, desc,
                                 [c.node_index for c in charts], progress)

    def build_quadrature(self, progress=lambda it, **kw: it, need_second: bool = True,
                         real: Optional[np.ndarray] = None, keep_basis: bool = False
                         ) -> list[ChartQuadrature]:
        """Gauss points of every chart; ``real`` (N,) bool excludes triangles touching ghost
        nodes (integrate over the sampled surface only); ``keep_basis`` keeps the basis."""
        from .departure_repair import split_departed_charts
        from .orientation import orient_atlas

        s = self.settings
        done = self._quadrature_of(range(len(self.charts_)), real, need_second, keep_basis,
                                   progress)
        self.quadrature_, frames = [q for q, _ in done], [f for _, f in done]
        # a chart that departs from its points is split and rebuilt (departure_repair)
        split_departed_charts(self, frames, real, need_second, keep_basis, progress)
        # a smooth chart across a crease leaves its samples' triangles by construction: with
        # atlas.allow_creases (the user accepted a creased cloud) it is flagged, not refused
        if not self.charts_faithful().all() and not (s.allow_failed_patches or s.allow_creases):
            raise AtlasError(self._departed_charts_message(refuse=True))
        check_chart_edges(self, real, refuse=not s.allow_failed_patches)  # ψ_κ off the rims
        orient_atlas(self, frames)  # chart_orientation_, orientation_, orientable_: one side for all
        return self.quadrature_

    def _map_patches(self, task, items: list, shared: dict, desc: str, node_sets: list,
                     progress) -> list:
        """``task(shared, item)`` for every patch on the run's executor
        (:mod:`pointatlas.executor`): in this process with ``progress`` lines, or as batched
        tasks on a cluster; the cost of a patch is its number of control points."""
        executor = current_executor()
        if not executor.distributed:
            items = progress(items, total=len(items), desc=desc)
        return executor.map(task, items, shared=shared, desc=desc,
                            costs=[len(J) for J in node_sets],
                            labels=[patch_tasks.patch_label(self.points_, J, k)
                                    for k, J in enumerate(node_sets)])

    def build(self, points, markers=None, progress=lambda it, **kw: it,
              real: Optional[np.ndarray] = None, keep_basis: bool = False) -> "Atlas":
        self.partition(points, markers)
        self.build_charts(progress)
        self.build_quadrature(progress, real=real, keep_basis=keep_basis)
        return self

    # -- use ---------------------------------------------------------------------------
    def quadrature_points(self) -> QuadraturePoints:
        q = self.quadrature_
        T = np.concatenate([c.tangents for c in q])
        S = None if q[0].second is None else np.concatenate([c.second for c in q])
        chart = np.concatenate([np.full(len(c.weights), k) for k, c in enumerate(q)])
        from .orientation import non_orientable_message

        o = self.orientation_report_  # normals of one orientation (orient_atlas)
        return QuadraturePoints(
            chart=chart, weights=np.concatenate([c.weights for c in q]),
            positions=np.concatenate([c.positions for c in q]),
            tangents=T, geometry=dg.manifold_geometry(
                T, S, orientation=o.signs[chart],
                unoriented=None if o.orientable else non_orientable_message(o)))

    def integrate(self, f: Callable[[QuadraturePoints], np.ndarray], per_chart: bool = False):
        """∫_M f dM ≈ Σ_κ Σ_g w_g J_κ ψ_κ f (thesis §3.4); f gets a :class:`QuadraturePoints`.

        With per_chart=True returns the (L,) chart contributions ∫_M ψ_κ f dM.
        """
        qp = self.quadrature_points()
        vals = np.asarray(f(qp), dtype=np.float64) * qp.weights
        parts = np.bincount(qp.chart, weights=vals, minlength=len(self.quadrature_))
        return parts if per_chart else float(parts.sum())

    def redundancy(self, definition: str = "used") -> float:
        """Quadrature redundancy: Gauss points of all charts over those of one cover of M.

        'used' (default, kept for the studies): the Gauss points kept (ψ_κ > tol_pu) over
            n_cover × rule size, n_cover the simplices of one triangulation of the N points
            (2N triangles for a closed surface, N segments for a closed curve; for d ≥ 3 the
            PU-weighted count of 'paper2').
        'paper2' (Paper 2 §1, Fig. 1): every Gauss point evaluated over Σ_κ Σ_g ψ_κ(x_g),
            the count of one non-overlapping cover at the charts' density (Σ_κ ψ_κ = 1).
        See :meth:`redundancy_report` for all the counts.
        """
        r = self.redundancy_report()
        if definition == "used":
            return r["used_over_triangulation"] if np.isfinite(r["used_over_triangulation"]) \
                else r["used_over_pu_count"]
        if definition == "paper2":
            return r["paper2"]
        raise InputError(f"definition = {definition!r} is invalid; use 'used' or 'paper2'.")

    def redundancy_report(self) -> dict[str, float]:
        """Gauss point counts behind :meth:`redundancy` and their ratios."""
        q = self.quadrature_
        d = self.charts_[0].xi_nodes.shape[1]
        rule = simplex_rule(d, self.settings.quadrature_order).n_points
        used = float(sum(len(c.weights) for c in q))
        evaluated = float(sum(c.n_candidates for c in q))
        pu_count = float(sum(c.pu.sum() for c in q))
        N = self.points_.shape[0]
        n_cover = {1: N, 2: 2 * N}.get(d)
        tri = np.nan if n_cover is None else float(n_cover * rule)
        return {"gauss_points_used": used, "gauss_points_evaluated": evaluated,
                "single_cover_pu_count": pu_count, "single_cover_triangulation": tri,
                "used_over_triangulation": used / tri if n_cover else np.nan,
                "used_over_pu_count": used / pu_count,
                "paper2": evaluated / pu_count}
