"""Charts that repair themselves, or a refusal that says why (issue 16, items 1–2).

A patch whose embedding fails the chart test (a fold, stress above ``max_stress`` or
95th-percentile distortion above ``max_distortion``; :func:`.partition.embedding_defects`)
is re-embedded with the geodesic embedders NLIE (thesis App. C, seeded by Isomap) and then
plain Isomap (thesis §2.2) before it is split again (:func:`.partition.refine_partition`, the thesis'
recursive METIS partitioning). A linear projection (PCA) folds a patch that wraps round a
thin tube; graph geodesics unroll it. A patch that fails with every embedder at the
smallest size or the depth limit is refused (:class:`AtlasError`) unless the user allows
failed patches, in which case its weight is reported.

Only the embedders that passed are used for the charts: :class:`EmbeddingAttempt` keeps the
embedding the test accepted, which the chart then reuses.
"""
from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from pointatlas.errors import InputError

#: the geodesic embedders tried, in this order, on a patch whose chart fails. NLIE first: it
#: is Isomap (its seed) relaxed to a locally isometric embedding, whose smoother ξ gives
#: better curvatures (5 000-point torus, PCA failing on 32 of 33 patches: Willmore error
#: 2.6e-3 with Isomap charts, 2.6e-4 with NLIE charts, 2.4e-4 before with PCA on 102 split
#: patches); plain Isomap is the fallback where NLIE fails.
GEODESIC_EMBEDDERS = ("nlie", "isomap")


class AtlasError(InputError):
    """The atlas of these points fails its own checks: no number is given for it."""


@dataclass
class EmbeddingAttempt:
    """One embedding of a control set J_κ and its chart-test verdict."""

    embedder: str            # entry-point name of the embedder ('pca', 'isomap', 'nlie', ...)
    xi: np.ndarray           # (|J|, d) embedded control points
    defects: dict            # embedding_defects(P_J, xi)
    passed: bool

    def badness(self, max_stress: float, max_distortion: float) -> tuple:
        """Order of failure: folds first, then the larger of stress and distortion over
        their bounds (a value < 1 passes)."""
        d = self.defects
        return (d.get("flip_fraction", 0.0) > 0.0,
                max(d.get("stress", 0.0) / max_stress, d.get("distortion", 1.0) / max_distortion))


def embedder_name(embedder) -> str:
    """The registry name of an embedder instance: the built-ins' class names lower-cased
    (PCA → 'pca', Isomap → 'isomap', NLIE → 'nlie'), as their entry points are named."""
    return type(embedder).__name__.lower()


def repair_neighbors(n_points: int, d: int) -> int:
    """k of the k-NN graph of the geodesic re-embedding of an n-point patch of dimension d.

    4(d+1) neighbours (12 on a surface, the Isomap default; two rings of a d-dimensional
    lattice) connect the graph on uneven samples and keep the graph geodesics within a few
    per cent of the surface ones, while their radius (about 2 spacings on a surface) stays
    well inside the reach of a surface resolved by 25 or more spacings round its thinnest
    tube (a larger k short-cuts across it). Capped at n − 1 for small patches.
    """
    return int(max(1, min(4 * (int(d) + 1), int(n_points) - 1)))


def repair_embedders(configured: Callable[[], object], d: int
                     ) -> list[tuple[str, Callable[[int], object]]]:
    """(name, factory(n_points) -> embedder) in the order they are tried on a patch: the
    configured embedder, then NLIE and Isomap (those not already configured), built through
    the registry with :func:`repair_neighbors` neighbours."""
    import pointatlas

    first = embedder_name(configured())
    chain: list[tuple[str, Callable[[int], object]]] = [(first, lambda n: configured())]
    for name in GEODESIC_EMBEDDERS:
        if name == first:
            continue
        cls = pointatlas.load_plugin("embedders", name)
        # NLIE: the default 50 stress neighbours (at most n − 1); the chart test needs a
        # stress below max_stress (2e-2), not a converged minimum: a relative length
        # tolerance of 1e-4 and 20 Newton steps (on 72 thin-tube patches, 10 steps passed as
        # many as 50 did, in a quarter of the time; 20 keeps a margin)
        kwargs = (lambda n: {"n_stress_neighbors": max(1, min(50, n - 1)), "tol": 1e-4,
                             "max_iter": 20}) if name == "nlie" else (lambda n: {})
        chain.append((name, lambda n, cls=cls, kw=kwargs: cls(
            n_neighbors=repair_neighbors(n, d), n_components=d, **kw(n))))
    return chain


class Fresh:
    """A picklable factory: a fresh deep copy of ``prototype`` per call (an unfitted embedder
    or approximant), so the factories of a run can be sent to Dask workers."""

    def __init__(self, prototype):
        self.prototype = prototype

    def __call__(self, *args):
        import copy

        return copy.deepcopy(self.prototype)


def embed_control_set(P: np.ndarray, chain, max_stress: float, max_distortion: float
                      ) -> Optional[EmbeddingAttempt]:
    """Embed the control points P (n, D) of a patch with the embedders of ``chain``
    (:func:`repair_embedders`) in turn until one passes the chart test; returns the passing
    embedding, else the least bad one. Pure: the same P gives the same attempt anywhere.

    The configured (first) embedder's errors are the user's and propagate; a geodesic one
    that fails (e.g. a disconnected k-NN graph) is skipped.
    """
    from pointatlas.errors import PointatlasError

    from .partition import embedding_defects

    best = None
    for i, (name, make) in enumerate(chain):
        try:
            if i == 0:                      # the configured embedder: errors are the user's
                xi = make(len(P)).fit_transform(P)
            else:                           # small dense problems: one thread
                with serial_threads():
                    xi = make(len(P)).fit_transform(P)
        except PointatlasError:
            if i == 0:
                raise
            continue                        # e.g. a disconnected k-NN graph: next one
        xi = np.asarray(xi, dtype=np.float64)
        if len(P) < 10:                     # too few points to test: kept as embedded
            return EmbeddingAttempt(name, xi, {}, True)
        defects = embedding_defects(P, xi)
        attempt = EmbeddingAttempt(name, xi, defects,
                                   chart_passes(defects, max_stress, max_distortion))
        if best is None or attempt.passed or (attempt.badness(max_stress, max_distortion)
                                              < best.badness(max_stress, max_distortion)):
            best = attempt
        if attempt.passed:
            break
    return best


@contextmanager
def serial_threads():
    """One BLAS and one numba thread: a patch's embedding is a small dense problem, on which
    parallel regions cost more than they save (and thrash on a loaded machine: a 300-point
    eigendecomposition took 7x longer on two busy BLAS threads than on one, measured)."""
    import numba

    from .chart import one_blas_thread

    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        with one_blas_thread():
            yield
    finally:
        numba.set_num_threads(threads)


def chart_passes(defects: dict, max_stress: float, max_distortion: float) -> bool:
    """The chart test: no fold, stress < max_stress, distortion < max_distortion."""
    return (defects["flip_fraction"] == 0.0 and defects["stress"] < max_stress
            and defects["distortion"] < max_distortion)


def _why(defects: dict, max_stress: float, max_distortion: float) -> str:
    reasons = []
    if defects.get("flip_fraction", 0.0) > 0:
        reasons.append(f"folded ({100 * defects['flip_fraction']:.2g} % of triangle pairs)")
    if defects.get("stress", 0.0) >= max_stress:
        reasons.append(f"stress {defects['stress']:.3g} > {max_stress:g}")
    if defects.get("distortion", 1.0) >= max_distortion:
        reasons.append(f"distortion {defects['distortion']:.3g} > {max_distortion:g}")
    return " and ".join(reasons) or "not connected"


def failed_patches_message(markers: np.ndarray, labels: np.ndarray, accepted: np.ndarray,
                           attempts: list[Optional[EmbeddingAttempt]], max_stress: float,
                           max_distortion: float, tried: list[str], point_fraction: float,
                           max_depth: int, refuse: bool = True) -> str:
    """One line: how many patches fail after repair, the share of the points on them (by the
    partition of unity), the worst three (centroid of their markers, count and diameter,
    why), and what to try; ``refuse``: the refusal, else the warning of an allowed atlas."""
    bad = np.flatnonzero(~accepted)

    def key(k):
        a = attempts[k]
        return (True, np.inf) if a is None else a.badness(max_stress, max_distortion)

    worst = sorted(bad, key=key, reverse=True)[:3]
    where = []
    for k in worst:
        Q = markers[labels == k]
        c = Q.mean(axis=0)
        diameter = 2.0 * float(np.max(np.linalg.norm(Q - c, axis=1)))
        why = "not connected" if attempts[k] is None else _why(attempts[k].defects, max_stress,
                                                               max_distortion)
        where.append(f"({', '.join(f'{v:.3g}' for v in c)}), {len(Q)} markers across "
                     f"{diameter:.3g}: {why}")
    head = (f"{bad.size} of {accepted.size} patches of the atlas fail the chart test even after "
            f"re-embedding ({', '.join(tried)}) and splitting (up to {max_depth} bisections); they "
            f"carry {100 * point_fraction:.3g} % of the points; the worst at " + "; ".join(where))
    if refuse:
        return (head + ". Their charts would make integrals, strains and energies wrong, so "
                "none are computed. Try more points (a denser sample there), a larger "
                "atlas.markers_per_patch, atlas.chart_reproduction=quartic (uneven points), or "
                "atlas.allow_failed_patches=true to get results flagged as unreliable.")
    return (head + ". atlas.allow_failed_patches=true keeps them: integrals, strains and "
            "energies may be wrong there (results flagged); more points, a larger "
            "atlas.markers_per_patch or atlas.chart_reproduction=quartic may repair them.")
