"""Linear Kirchhoff–Love analysis of a point-set shell, from points to displacements.

Thesis §4 / Paper 1 §3–4 on the atlas of Paper 2: (1) find the boundary of the sampled
surface and add ghost nodes beyond it (Paper 1 §4.1.2); (2) build the atlas on all nodes with
the real markers, integrating only over the sampled surface; (3) assemble the stiffness from
the membrane and bending strain–displacement matrices (Paper 1 App. C); (4) nodal loads;
(5) supports as constraints, solved by an augmented Lagrangian (App. D, thesis App. E.2);
(6) displacements at the points, u(x_a) = Σ_b p_b(ξ_a) U_b.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pointatlas.errors import InputError
from pointatlas_kit.surface_model import SurfaceModel


@dataclass
class ShellModel(SurfaceModel):
    """A :class:`pointatlas_kit.surface_model.SurfaceModel` with what a shell solve needs
    and produces (arrays in the source's length units)."""

    material: object = None
    stiffness: object = None
    forces: np.ndarray | None = None          # (N + G, 3)
    constraints: object = None
    nodal_displacement: np.ndarray | None = None  # (N + G, 3) U
    displacement: np.ndarray | None = None    # (N, 3) u(x_a)
    solve_info: object = None

    @property
    def dof(self) -> int:
        return 3 * self.nodes.shape[0]


def _timed(times: dict, key: str):
    """Wall time of a stage less numba's compilation in it (pointatlas.jit_time)."""
    from pointatlas.jit_time import StageTimer

    return StageTimer(times, key)


def build_model(cloud, settings, atlas_settings, make_embedder, make_lme, make_pu,
                log=None, linear: bool = True) -> ShellModel:
    """Boundary, ghosts, atlas and quadrature of a shell point cloud (no physics yet), by
    the kit (:func:`pointatlas_kit.surface_model.build_surface_model`, order-2 basis);
    ``linear``: for the linear analysis (a model too large for memory is then told about
    ``physics.streamed_assembly``)."""
    from pointatlas_kit.surface_model import build_surface_model

    from .material import ShellMaterial

    material = ShellMaterial(young_modulus=settings.young_modulus,
                             poisson_ratio=settings.poisson_ratio, thickness=settings.thickness)
    material.check()
    m = build_surface_model(cloud, atlas_settings, make_embedder, make_lme, make_pu, order=2,
                            ghost_layers=settings.ghost_layers, block=3, log=log,
                            keep_basis=not settings.streamed_assembly,
                            memory_fix="" if settings.streamed_assembly or not linear else
                            "physics.streamed_assembly=true (a linear analysis that does not "
                            "keep the basis, most of this memory)")
    return ShellModel(m.points, m.nodes, m.boundary, m.curves, m.spacing, m.atlas,
                      m.quadrature, m.times, material=material)


def solve_linear(model: ShellModel, settings, log=None) -> ShellModel:
    """Stiffness, loads, supports and the augmented-Lagrangian solve; fills ``model``."""
    from pointatlas_atlas.evaluation import basis_at_nodes
    from pointatlas_solvers.augmented_lagrangian import solve_augmented

    t = model.times
    N_all = model.nodes.shape[0]
    with _timed(t, "assembly"):
        K = regularize_ghosts(*stiffness(model), model)
    with _timed(t, "loads"):
        F = assemble_loads(model, settings, log)
    with _timed(t, "constraints"):
        cons = assemble_supports(model, settings)
    with _timed(t, "solve"):
        U, _, info = solve_augmented(K, F.ravel(), cons.matrix, cons.rhs, settings.penalty,
                                     settings.constraint_tol, backend=settings.solver)
    U = U.reshape(-1, 3)
    with _timed(t, "post"):
        basis, _, _ = basis_at_nodes(model.atlas, np.arange(model.points.shape[0]), order=0)
        u = basis.to_csr(N_all) @ U
    if log is not None:
        log.info("solved %d DOF: %d AL iteration(s), constraint violation %.2e",
                 3 * N_all, info.iterations, info.violation)
    model.stiffness, model.forces, model.constraints = K, F, cons
    model.nodal_displacement, model.displacement, model.solve_info = U, u, info
    return model


def stiffness(model: ShellModel):
    """(K at U = 0 (CSR), the nodes a Gauss point's basis touches or None): from the
    model's quadrature, or, on a model built without the basis
    (``physics.streamed_assembly``), chart group by chart group on the run's executor
    (:func:`pointatlas_kit.streamed_tangent.streamed_tangent`), refusing samples no Gauss
    point integrates."""
    from .linear import linear_stiffness

    if model.quadrature is not None:
        return linear_stiffness(model.quadrature, model.material), None
    from pointatlas_kit.fields import FieldLayout
    from pointatlas_kit.streamed_tangent import streamed_tangent
    from pointatlas_kit.surface_model import check_every_point_integrated

    from .shell_energy import DISPLACEMENT, ShellEnergy

    mat, n = model.material, model.nodes.shape[0]
    K = streamed_tangent(model.atlas, FieldLayout([DISPLACEMENT], n),
                         [ShellEnergy(mat.young_modulus, mat.poisson_ratio, mat.thickness)])
    touched = np.zeros(n, bool)
    touched[np.flatnonzero(np.diff(K.indptr))] = True
    check_every_point_integrated(touched, np.arange(n) < model.points.shape[0])
    return K.tocsr(), touched


def assemble_loads(model: ShellModel, settings, log=None) -> np.ndarray:
    """Nodal forces (N + G, 3) of all configured loads at load factor 1."""
    from .loads import line_load, point_load, surface_load

    F = np.zeros((model.nodes.shape[0], 3))
    normals = None
    for ld in settings.loads:
        if ld.kind == "point":
            f, where, dist = point_load(model.atlas, ld.at, ld.force, model.spacing,
                                        settings.max_load_offset, points=model.points)
            if log is not None:
                log.info("point load %s at %s (projected %.3g away)", list(ld.force),
                         np.round(where, 6).tolist(), dist)
            F += f
        elif ld.kind in ("surface", "pressure"):
            if ld.kind == "pressure" and normals is None:
                normals = pressure_normals(model)
                if log is not None:
                    log.info("pressure acts along the atlas normals (orientation: %s)",
                             model.atlas.orientation_)
            F += surface_load(model.quadrature, F.shape[0], ld.force, ld.pressure, normals)
        else:
            F += line_load(model.atlas, model.points, model.boundary, model.curves,
                           ld.where, ld.force, model.spacing)
    return F


def assemble_supports(model: ShellModel, settings):
    """Constraints C U = g of the supports, checked against unheld rigid motions."""
    from .constraints import check_rigid_motions, support_constraints

    cons = support_constraints(model.atlas, model.points, model.boundary, model.curves,
                               settings.supports, model.spacing, settings.segment_points)
    check_rigid_motions(cons.matrix, model.nodes, settings.supports)
    return cons


def regularize_ghosts(K, seen, model: ShellModel, eps: float = 1e-10):
    """K plus the weak ghost springs (:func:`pointatlas_kit.surface_model.ghost_springs`,
    ``seen`` the nodes the quadrature touches, None: the model's quadrature) on its
    diagonal."""
    from scipy.sparse import diags

    from pointatlas_kit.surface_model import ghost_springs

    return (K + diags(ghost_springs(K.diagonal(), model, 3, eps, seen))).tocsr()


def pressure_normals(model: ShellModel) -> np.ndarray:
    """Unit normals (m, 3) at the shell's quadrature points, of the atlas's one orientation
    (:mod:`pointatlas_atlas.orientation`): outward on a surface that encloses a volume, along
    ``atlas.orientation`` (n·e > 0 on average) on an open one. A pressure p is the traction
    p n: p > 0 pushes a closed shell outwards and an open one towards ``atlas.orientation``.

    Refused (ConfigError) on an open surface whose orientation the user has not fixed (the
    side would be the first chart's, an accident of the embedding), and (InputError) on a
    non-orientable cloud.
    """
    from pointatlas.errors import ConfigError
    from pointatlas_atlas.orientation import non_orientable_message

    atlas, q = model.atlas, model.quadrature
    o = atlas.orientation_report_
    if not o.orientable:
        raise InputError(f"a pressure load needs a normal, but {non_orientable_message(o)}")
    if "first_chart" in o.mode:
        raise ConfigError(
            "a pressure load on an open surface needs a fixed orientation: set "
            "atlas.orientation=[nx, ny, nz], the side the normal n faces (n·e > 0 on average; "
            "the traction is p n, so p > 0 pushes the surface towards it), e.g. "
            "atlas.orientation=[0, 0, 1].")
    return q.normals


def displacement_at(model: ShellModel, x) -> tuple[np.ndarray, np.ndarray]:
    """(u (3,), projected point (3,)) at the surface point nearest to ``x``
    (:func:`pointatlas_kit.surface_model.values_at`)."""
    from pointatlas_kit.surface_model import values_at

    u, p = values_at(model.atlas, model.nodal_displacement, np.reshape(x, (1, 3)))
    return u[0], p[0]
