"""The ``kirchhoff_love`` physics plugin: thin shells on a point-set atlas (thesis §4)."""
from __future__ import annotations

from dataclasses import fields
from typing import ClassVar

from pointatlas.stores_config import stores_config

from .displacement_field import DISPLACEMENT
from .settings import ShellSettings, check_settings


@stores_config
class KirchhoffLove:
    """Kirchhoff–Love shell, St. Venant–Kirchhoff material, LME charts glued by the atlas PU.

    ``solve(ctx, cloud=..., atlas_settings=...)`` runs the linear analysis and returns the
    displacement field as a Dataset; the model (atlas, stiffness, constraints) is kept in
    ``model_`` for post-processing (scikit-learn convention for learned state).
    """

    Config = ShellSettings
    #: the kit fields of the shell energy (:mod:`.shell_energy`)
    fields: ClassVar[tuple] = (DISPLACEMENT,)
    description: ClassVar[str] = (
        "Kirchhoff–Love thin shell on the atlas: linear analysis with supports by augmented "
        "Lagrangian, ghost nodes at boundaries (thesis §4, Papers 1–2).")
    #: Config values of a small problem for pointatlas.testing.check_physics: clamped on the
    #: whole boundary of its open patch (in [0, 1]² × [0, 0.35]) under a surface load
    conformance_case: ClassVar[dict] = {
        "supports": [{"kind": "clamped", "where": {"box": [-1.0, -1.0, -1.0, 2.0, 2.0, 2.0]}}],
        "loads": [{"kind": "surface", "force": [0.0, 0.0, -1.0]}]}

    def energies(self, positions=None) -> list:
        """The shell's kit energies: membrane + bending (:class:`.shell_energy.ShellEnergy`)."""
        from .shell_energy import ShellEnergy

        return [ShellEnergy(self.young_modulus, self.poisson_ratio, self.thickness)]

    def discrete_energy(self, patch: dict):
        """The shell energy on quadrature arrays (the conformance suite's view)."""
        from pointatlas_kit.energy import DiscreteEnergy

        return DiscreteEnergy(self.fields, self.energies(), patch)

    def settings(self) -> ShellSettings:
        return ShellSettings(**{f.name: getattr(self, f.name) for f in fields(ShellSettings)})

    def check_config(self) -> None:
        """The checks of :meth:`shell_settings`, at start-up (before any work)."""
        self.shell_settings()

    def shell_settings(self) -> ShellSettings:
        """The settings with supports, loads and selectors as dataclasses, checked."""
        s = _as_settings(self.settings())
        check_settings(s)
        return s

    @staticmethod
    def factories(ctx, atlas_settings) -> dict:
        """make_embedder / make_lme / make_pu for :func:`.analysis.build_model`."""
        from pointatlas.errors import ConfigError

        a = atlas_settings
        # the shell's make_lme below builds the plain LME basis: refuse the geometry-only chart
        # options rather than ignore them
        if getattr(a, "chart_hessians", "exact") != "exact":
            raise ConfigError(
                f"chart_hessians = {a.chart_hessians!r} is not available for shells: the bending "
                "energy needs the exact LME Hessians (with the diffuse 'consistent' ones a "
                "clamped plate comes out 57 % too soft). Remove the override; 'consistent' is "
                "for curvature integrals (study=surface_geometry).")
        if getattr(a, "chart_reproduction", "linear") != "linear":
            raise ConfigError(
                f"chart_reproduction = {a.chart_reproduction!r} is not available for shells: "
                "the displacement basis must be the LME basis with its exact derivatives (the "
                "polynomial fit's diffuse derivatives are not the derivatives of its values). "
                "Remove the override; the polynomial-fit charts are for geometry "
                "(study=surface_geometry).")
        from pointatlas_kit.surface_model import atlas_factories

        return atlas_factories(ctx, a, physics="kirchhoff_love")

    def solve(self, ctx, *, cloud, atlas_settings):
        """Linear analysis of ``cloud``; returns displacement, forces and sizes (xr.Dataset)."""
        from .analysis import build_model, solve_linear
        from .results import field_dataset

        s = self.shell_settings()
        model = build_model(cloud, s, atlas_settings, **self.factories(ctx, atlas_settings),
                            log=ctx.log)
        solve_linear(model, s, log=ctx.log)
        self.model_ = model
        ds = field_dataset(model)
        warning = model.atlas.refinement_warning()  # failed patches, kept by the user's choice
        if warning:
            ds.attrs["warnings"] = warning
        # the side the normals (and pressures) of the atlas face: 'outward', the user's
        # atlas.orientation '[nx, ny, nz]', 'first_chart' (not fixed) or 'none'
        ds.attrs["normal_orientation"] = str(model.atlas.orientation_)
        from pointatlas_solvers.linear_backends import resolve_backend

        ds.attrs["linear_solver"] = resolve_backend(s.solver)  # 'auto' resolved
        return ds

    # -- what studies ask of a solved or built shell (the protocol; no study reads model_) --
    def evaluate(self, name: str, x):
        """(values (k, 3), projected points (k, 3)) of field ``name`` ('displacement') at the
        surface points nearest to ``x`` (k, 3), after :meth:`solve`."""
        from pointatlas_kit.surface_model import values_at

        model = self._solved()
        if name != "displacement":
            from pointatlas.errors import ConfigError

            raise ConfigError(f"kirchhoff_love has the field 'displacement', not {name!r}.")
        return values_at(model.atlas, model.nodal_displacement, x)

    def export_vtp(self, path, magnification: float = 1.0, units_system: str = "SI"):
        """The solved shell as a ParaView .vtp file: surface triangles, ``u``, |u|, the
        deformed shape, each array's units in ``units_system`` (:func:`.results.write_vtp`)."""
        from .results import write_vtp

        return write_vtp(self._solved(), path, magnification, units_system)

    def surface_triangles(self, problem=None):
        """(T, 3) indices into the sampled points: the triangles of the surface of the built
        path ``problem`` (from :meth:`path_problem`), or of the solved shell without one
        (:func:`pointatlas_kit.surface_mesh.surface_triangles`), for ParaView files."""
        from pointatlas_kit.surface_mesh import surface_triangles

        model = self._solved() if problem is None else problem.model
        return surface_triangles(model.atlas, model.points.shape[0])

    def path_problem(self, ctx, *, cloud, atlas_settings):
        """A :class:`.path_problem.ShellPath` (equilibrium problem, monitors, point fields)."""
        from .path_problem import build_path

        return build_path(self, ctx, cloud, atlas_settings)

    def _solved(self):
        model = getattr(self, "model_", None)
        if model is None or model.nodal_displacement is None:
            from pointatlas.errors import PointatlasError

            raise PointatlasError("kirchhoff_love is not solved yet: call solve first.")
        return model


def _as_settings(s: ShellSettings) -> ShellSettings:
    """Supports, loads and selectors as dataclasses even when they came as dicts."""
    from pointatlas_kit.selectors import Selector
    from .settings import Load, Support

    def sel(x):
        return x if x is None or isinstance(x, Selector) else Selector(**dict(x))

    s.supports = [x if isinstance(x, Support) else Support(**dict(x)) for x in s.supports]
    s.loads = [x if isinstance(x, Load) else Load(**dict(x)) for x in s.loads]
    for family, items in (("supports", s.supports), ("loads", s.loads)):
        for i, x in enumerate(items):
            x.where = sel(x.where)
            if x.where is not None and x.where.name == "selector":
                x.where.name = f"physics.{family}[{i}].where"
    return s
