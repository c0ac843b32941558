"""From a point cloud to what every physics on a surface needs: boundary, ghosts, atlas,
quadrature (no physics).

Thesis §4 / Paper 1 §4.1.2 and Paper 2 §3: (1) the boundary of the sampled surface and its
curves, with ghost nodes beyond it so that the LME basis is not one-sided there; (2) the
atlas on all nodes with the real markers; (3) the :class:`~.atlas_quadrature.
AtlasQuadrature` over the sampled surface only (triangles touching a ghost are not
integrated), with chart derivatives to the order the fields need.

The charts use the run's choices through the registry (``embedder=``, ``approximant=``),
with the atlas settings' γ and tolerance; :func:`atlas_factories` builds them.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from pointatlas.errors import ConfigError, InputError

#: approximants that can be the basis of a chart (reproduce linear functions)
CHART_APPROXIMANTS = ("lme", "mls")
#: approximants whose chart basis has exact derivatives of its values (order 1 and 2)
DERIVATIVE_APPROXIMANTS = ("lme", "mls")


@dataclass
class SurfaceModel:
    """A sampled surface ready for physics (arrays in the source's length units)."""

    points: np.ndarray        # (N, 3) the sampled (real) points
    nodes: np.ndarray         # (N + G, 3) control points: real points, then ghosts
    boundary: np.ndarray      # (N,) bool
    curves: list
    spacing: float            # median nearest-neighbour distance (length)
    atlas: object
    quadrature: object        # AtlasQuadrature
    times: dict = field(default_factory=dict)

    @property
    def n_ghosts(self) -> int:
        return self.nodes.shape[0] - self.points.shape[0]


def atlas_factories(ctx, atlas_settings, physics: str | None = None, embedder: str = "pca",
                    **chart_options) -> dict:
    """make_embedder / make_lme / make_pu of the run's ``embedder=`` and ``approximant=``
    choices (through the registry; ``approximant`` unset means ``lme``; without a run,
    ``ctx`` None as in scripts and tests: the plugin ``embedder`` in 2-D), with the chart
    approximant's γ and tolerance from the atlas settings (``atlas.gamma_lme``,
    ``atlas.tol_lme``) and its other settings from the ``approximant`` group.

    A choice the charts cannot use is refused: an approximant that is not a chart basis
    (Shepard reproduces only constants), for a ``physics`` one without exact derivatives of
    its values, and an ``approximant.gamma``/``tol`` set to another value than the atlas's
    (one place holds them: the atlas settings).
    """
    a = atlas_settings
    name = (ctx.choices.get("approximant") if ctx is not None else None) or "lme"
    if name not in CHART_APPROXIMANTS:
        raise ConfigError(
            f"approximant={name} cannot be the basis of the atlas charts (a chart must "
            "reproduce linear functions); use approximant=lme (the default). The partition "
            "of unity is the atlas's Shepard functions (atlas.gamma_pu).")
    if physics and name not in DERIVATIVE_APPROXIMANTS:
        raise ConfigError(
            f"approximant={name} cannot carry {physics}: its fields need the chart basis with "
            f"exact derivatives of its values; use approximant={DERIVATIVE_APPROXIMANTS[0]}.")
    chosen = {}
    if ctx is not None and ctx.choices.get("approximant"):
        import dataclasses

        from pointatlas.context import plugin_kwargs
        from pointatlas.registry import load_plugin

        chosen = plugin_kwargs(ctx.config.get("approximant"))
        config = getattr(load_plugin("approximants", name), "Config", None)
        defaults = {f.name: f.default for f in dataclasses.fields(config)} if config else {}
        for key, atlas_key in (("gamma", "gamma_lme"), ("tol", "tol_lme")):
            if key in chosen and chosen[key] != defaults.get(key) and \
                    chosen[key] != getattr(a, atlas_key):
                raise ConfigError(
                    f"approximant.{key} = {chosen[key]!r} is not what the charts use: the atlas "
                    f"settings hold it. Write atlas.{atlas_key}={chosen[key]!r} instead.")
        chosen = {k: v for k, v in chosen.items() if k not in ("gamma", "tol", "outside")}
    options = {**chosen, **chart_options}
    if ctx is None:
        from pointatlas.registry import load_plugin

        def make(family, plugin, **kw):
            return load_plugin(family, plugin)(**kw)
    else:
        make = ctx.make
    return dict(
        make_embedder=(lambda: ctx.plugin("embedder")) if ctx is not None else
        (lambda: make("embedders", embedder, n_components=2)),
        make_lme=lambda: make("approximants", name, gamma=a.gamma_lme, tol=a.tol_lme,
                              outside="flag", **options),
        make_pu=lambda: make("approximants", "shepard", gamma=a.gamma_pu, tol=a.tol_pu,
                             outside="flag"))


def check_surface_cloud(cloud, n_neighbors: int, allow_creases: bool = False) -> str | None:
    """Refuse (InputError, one line with where and the fix) a cloud a physics on one smooth
    surface cannot carry: creases or non-disc neighbourhoods
    (:mod:`pointatlas_atlas.cloud_checks`), isolated points, or several components (a
    physics is solved on one connected surface; give each component its own run).

    With ``allow_creases`` a cloud whose only defect is crease points (e.g. fillets sampled
    at about one spacing per curvature radius) is kept: the reason is returned as the
    warning the results carry."""
    from pointatlas_atlas.cloud_checks import check_cloud, components_message, verdict, where

    check = check_cloud(cloud.points, n_neighbors)
    reason, kept = verdict(cloud.points, check, cloud.name, allow_creases)
    if reason:
        raise InputError(reason)
    comp = check.components
    if len(comp.sizes) > 1:
        raise InputError(f"{cloud.name}: {components_message(comp)}; a physics is solved on "
                         "one connected surface: give each component its own run (e.g. "
                         "source=file with the points of one part).")
    if comp.n_isolated:
        iso = comp.labels < 0
        raise InputError(f"{cloud.name}: {comp.n_isolated} isolated point(s), far from the "
                         f"surface, e.g. near {where(cloud.points[iso])}: remove them (they "
                         "would carry nodes of no chart).")
    return kept


def build_surface_model(cloud, atlas_settings, make_embedder, make_lme, make_pu, *,
                        order: int, ghost_layers: int = 2, block: int = 1,
                        log=None, keep_basis: bool = True, solve: bool = True,
                        memory_fix: str = "") -> SurfaceModel:
    """Boundary, ghosts, atlas and quadrature (basis to chart derivative ``order``).

    Refuses before any work a model that cannot fit in memory: the atlas with its basis
    plus the tangent of ``block`` DOFs per node and its solve
    (:func:`pointatlas_atlas.memory_estimate.estimate_tangent_bytes`). Without
    ``keep_basis`` the atlas keeps only its charts and Gauss points (``quadrature`` is None):
    the model of :func:`.streamed_tangent.streamed_tangent`, which rebuilds the basis group
    by group. Without ``solve`` (an assembly only) the estimate counts the tangent's parts
    and their sum instead of the tangent and its factorisation. ``memory_fix``: one more way
    out the refusal names (e.g. the physics' streamed assembly)."""
    import time

    from pointatlas_atlas.atlas import Atlas
    from pointatlas_atlas.boundary import boundary_curves, boundary_mask
    from pointatlas_atlas.ghosts import ghost_points

    from .atlas_quadrature import atlas_quadrature

    times: dict = {}
    P = cloud.points
    if P.shape[1] != 3:
        raise InputError(f"a surface physics needs points in R^3; {cloud.name} has "
                         f"D = {P.shape[1]}.")
    spacing = float(np.median(cKDTree(P).query(P, k=2)[0][:, 1]))
    from pointatlas.jit_time import compile_seconds

    c0, t0 = compile_seconds(), time.perf_counter()
    kept = check_surface_cloud(cloud, atlas_settings.graph_neighbors,
                               getattr(atlas_settings, "allow_creases", False))
    boundary = boundary_mask(P)
    curves = boundary_curves(P, boundary) if boundary.any() else []
    G = (ghost_points(P, boundary, layers=ghost_layers)
         if boundary.any() and ghost_layers > 0 else np.zeros((0, 3)))
    nodes = np.vstack([P, G])
    real = np.arange(nodes.shape[0]) < P.shape[0]
    markers = cloud.markers if cloud.markers is not None else P
    c1, t1 = compile_seconds(), time.perf_counter()
    atlas = Atlas(atlas_settings, make_embedder, make_lme, make_pu)
    atlas.kept_defects_ = [kept] if kept else []
    from pointatlas_atlas.memory_estimate import estimate_tangent_bytes, support_size

    s = atlas_settings
    tangent = estimate_tangent_bytes(nodes.shape[0], block,
                                     support_size(2, s.gamma_lme, s.tol_lme),
                                     # no solve: the streamed parts (node pairs of several
                                     # groups counted in each: 1.48 K on the 2·10⁴
                                     # hemisphere), summed into K in their place
                                     **({} if solve else {"copies": 1.5}))
    atlas.partition(nodes, markers, keep_basis=keep_basis, extra_bytes=tangent,  # AtlasError:
                    extra_what=f"a tangent of {block} DOF per node",     # charts fail
                    extra_fix=memory_fix)
    warning = atlas.refinement_warning()  # only with atlas.allow_failed_patches=true
    if warning and log is not None:
        log.warning(warning)
    c2, t2 = compile_seconds(), time.perf_counter()
    atlas.build_charts()
    c3, t3 = compile_seconds(), time.perf_counter()
    atlas.build_quadrature(real=real, keep_basis=keep_basis, need_second=order >= 2)
    check_dropped_quadrature(atlas)
    quadrature = atlas_quadrature(atlas, order, release_basis=True) if keep_basis else None
    c4, t4 = compile_seconds(), time.perf_counter()
    # stage times without numba's compilation (pointatlas.jit_time), which a process's first
    # model pays wherever it first calls a kernel
    times.update(boundary=(t1 - t0) - (c1 - c0), partition=(t2 - t1) - (c2 - c1),
                 charts=(t3 - t2) - (c3 - c2), quadrature=(t4 - t3) - (c4 - c3))
    if quadrature is not None:
        touched = np.zeros(nodes.shape[0], bool)
        touched[quadrature.indices] = True
        check_every_point_integrated(touched, real)
    if log is not None:
        log.info("%d points (%d on the boundary, %d curves) + %d ghosts; %d patches, "
                 "%d quadrature points", P.shape[0], int(boundary.sum()), len(curves),
                 G.shape[0], len(atlas.charts_), sum(len(c.weights) for c in atlas.quadrature_))
    return SurfaceModel(P, nodes, boundary, curves, spacing, atlas, quadrature, times)


#: the largest partition-of-unity weight ψ_κ a dropped Gauss point may carry (a point where
#: the chart's basis does not exist: outside the hull of its nodes, or refused by the basis)
LOST_PU_LIMIT = 1.0e-3


def check_every_point_integrated(touched: np.ndarray, real: np.ndarray) -> None:
    """Refuse a model where a sample (``real`` node) carries no basis function at any Gauss
    point (``touched`` False): its DOFs would be free."""
    lonely = np.flatnonzero(real & ~touched)
    if lonely.size:
        raise InputError(
            f"{lonely.size} point(s) (first: {lonely[:5].tolist()}) lie in no chart's "
            "quadrature: the point cloud is too sparse or irregular there for the chart "
            "support. Sample the surface more densely or lower atlas.markers_per_patch.")


def check_dropped_quadrature(atlas) -> None:
    """Refuse an atlas whose charts dropped Gauss points of real weight (ψ_κ above
    :data:`LOST_PU_LIMIT`): the integrals would miss part of the surface. Measured 0 on
    all 58 models the kit, physics and studies tests build (LME charts); a cubic moving
    least-squares basis on pyvista's UV sphere loses the poles (ψ = 1)."""
    lost = [c.lost_pu for c in atlas.quadrature_]
    k = int(np.argmax(lost)) if lost else 0
    if lost and lost[k] > LOST_PU_LIMIT:
        name = type(atlas.charts_[k].approximant).__name__
        raise InputError(
            f"chart {k}'s basis ({name}) does not exist at some of its quadrature points, "
            f"where the partition of unity is up to {lost[k]:.3g}: the surface would not be "
            "integrated there. The points are too uneven or sparse for this basis there "
            "(approximant=lme carries the most uneven points); or sample more densely.")


def values_at_nodes(atlas, U_nodes: np.ndarray, nodes) -> np.ndarray:
    """Field values u(x_a) = Σ_b p_b(ξ_a) U_b at control points ``nodes`` (k, components)."""
    from pointatlas_atlas.evaluation import basis_at_nodes

    basis, _, _ = basis_at_nodes(atlas, np.asarray(nodes, np.int64), order=0)
    return basis.to_csr(U_nodes.shape[0]) @ U_nodes


def values_at(atlas, U_nodes: np.ndarray, x) -> tuple[np.ndarray, np.ndarray]:
    """(u (k, components), projected points (k, 3)) at the surface points nearest to ``x``."""
    from pointatlas_atlas.evaluation import basis_at
    from pointatlas_atlas.projection import closest_point

    proj = closest_point(atlas, np.atleast_2d(np.asarray(x, dtype=np.float64)))
    b = basis_at(atlas, proj.chart, proj.xi, order=0)
    return b.to_csr(U_nodes.shape[0]) @ U_nodes, proj.point


def ghost_springs(diagonal: np.ndarray, model: SurfaceModel, block: int,
                  eps: float = 1e-10, seen: np.ndarray | None = None) -> np.ndarray:
    """(block·n_nodes,) spring stiffness per DOF: ε·mean(diag K) on ghost DOFs and
    mean(diag K) on DOFs no quadrature point sees (``seen`` (n_nodes,) bool, by default from
    the model's quadrature). A ghost far out carries basis functions that are ~0 on the
    sampled surface (cut off by the LME tolerance), so its DOFs are nearly free: the spring
    pins them without changing the field on the surface noticeably."""
    n = model.nodes.shape[0]
    scale = float(np.mean(diagonal))
    node_w = np.zeros(n)
    node_w[model.points.shape[0]:] = eps
    if seen is None:
        seen = np.zeros(n, bool)
        seen[model.quadrature.indices] = True
    node_w[~np.asarray(seen, bool)] = 1.0
    return np.repeat(node_w * scale, block)
