"""The ``kirchhoff_love`` physics plugin: thin shells on a point-set atlas (thesis §4)."""
from __future__ import annotations

from typing import ClassVar

from pointatlas.stores_config import stores_config

from .settings import ShellSettings, check_settings


@stores_config
class KirchhoffLove:
    """Kirchhoff–Love shell, St. Venant–Kirchhoff material, LME charts glued by the atlas PU.

    ``solve(ctx, cloud=..., atlas_settings=...)`` runs the linear analysis and returns the
    displacement field as a Dataset; the model (atlas, stiffness, constraints) is kept in
    ``model_`` for post-processing (scikit-learn convention for learned state).
    """

    Config = ShellSettings
    description: ClassVar[str] = (
        "Kirchhoff–Love thin shell on the atlas: linear analysis with supports by augmented "
        "Lagrangian, ghost nodes at boundaries (thesis §4, Papers 1–2).")

    def settings(self) -> ShellSettings:
        return ShellSettings(**{k: getattr(self, k) for k in ShellSettings.__dataclass_fields__})

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
        return dict(
            make_embedder=lambda: ctx.plugin("embedder"),
            make_lme=lambda: ctx.make("approximants", "lme", gamma=a.gamma_lme, tol=a.tol_lme,
                                      outside="flag"),
            make_pu=lambda: ctx.make("approximants", "shepard", gamma=a.gamma_pu, tol=a.tol_pu,
                                     outside="flag"))

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
        return ds


def _as_settings(s: ShellSettings) -> ShellSettings:
    """Supports, loads and selectors as dataclasses even when they came as dicts."""
    from .selectors import Selector
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
