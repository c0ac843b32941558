"""Linear thin-shell analysis of a point cloud and its reference displacement (thesis §4).

The source gives the points of the shell's middle surface; the ``kirchhoff_love`` physics
plugin builds the atlas (with ghost nodes beyond the boundary), applies the supports and
loads of its config and solves. The study reads the displacement at ``reference_point``
along ``reference_direction`` (the sign convention of the published value), compares it with
``references`` and writes ``shell.vtp`` for ParaView (``write_vtp``): the surface's triangles
with ``u``, ``u_magnitude``, ``deformed`` (x + magnification·u) and ``on_boundary``, each
array's units in the field data (:mod:`pointatlas_kit.paraview`); Warp By Vector with ``u``
at the field value ``magnification`` draws the deformed shape of the report's picture.
Obstacle course references: BENCHMARKS.md (plate L1337, Scordelis–Lo and hemisphere L1343,
cylinder L1427 of the thesis).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, List

import numpy as np
from pointatlas_atlas.settings import AtlasSettings

from pointatlas.stores_config import stores_config


#: markers per patch of a shell's atlas unless atlas.markers_per_patch says otherwise
SHELL_MARKERS_PER_PATCH = 100


@dataclass
class ShellStudySettings(AtlasSettings):
    """Where and against what to read the result. The atlas parameters inherited from
    :class:`AtlasSettings` are the deprecated ``study.*`` spellings of ``atlas.*``."""

    reference_point: List[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    reference_direction: List[float] = field(default_factory=lambda: [0.0, 0.0, -1.0])
    references: List[float] = field(default_factory=list)
    reference_labels: List[str] = field(default_factory=list)
    magnification: float = 0.0      # 0: deformed shape scaled so max |u| is 10 % of the size
    write_vtp: bool = True


@stores_config
class ShellStudy:
    """Build the shell's atlas, solve, read the reference displacement, compare, export."""

    Config = ShellStudySettings
    description: ClassVar[str] = (
        "Linear Kirchhoff–Love analysis of a point-set shell: displacement at a reference "
        "point vs published values, deformed shape (.vtp).")

    def atlas_settings(self, ctx=None) -> AtlasSettings:
        """The run's ``atlas.*`` settings (the old ``study.*`` spellings still honoured, with a
        deprecation message); shells default to 100 markers per patch."""
        from pointatlas_atlas.plugin import study_atlas_settings

        return study_atlas_settings(ctx, self, markers_per_patch=SHELL_MARKERS_PER_PATCH)

    def check_config(self) -> None:
        """Start-up checks: the atlas settings and the magnification of the deformed shape."""
        import math

        from pointatlas.errors import ConfigError

        self.atlas_settings().check()
        m = self.magnification
        if not (isinstance(m, (int, float)) and math.isfinite(m) and m >= 0):
            raise ConfigError(f"magnification={m!r} is invalid: it must be a finite number >= 0 "
                              "(0 scales the deformed shape so that max |u| is 10 % of the size).")

    def run(self, ctx):
        from pointatlas.errors import ConfigError

        if ctx.plugin_name("physics") != "kirchhoff_love":
            raise ConfigError("study=shell needs physics=kirchhoff_love (the shell model); "
                              f"got physics={ctx.choices.get('physics')!r}.")
        if len(self.reference_labels) not in (0, len(self.references)):
            raise ConfigError("study.reference_labels must name each of study.references.")
        atlas_settings = self.atlas_settings(ctx)
        atlas_settings.check()
        with ctx.timed("source"):
            cloud = ctx.plugin("source").load(ctx.rng("source"))
        physics = ctx.plugin("physics")
        with ctx.timed("analysis"):
            ds = physics.solve(ctx, cloud=cloud, atlas_settings=atlas_settings)
        out = self._results(ctx, ds, physics, cloud)
        if ds.attrs.get("warnings"):
            out.attrs["warnings"] = ds.attrs["warnings"]
        return out

    def _results(self, ctx, ds, physics, cloud):
        """Reference displacement, errors and the .vtp, through the physics protocol."""
        e = np.asarray(self.reference_direction, dtype=np.float64)
        e = e / np.linalg.norm(e)
        u, x = physics.evaluate("displacement", np.reshape(self.reference_point, (1, 3)))
        u, x = u[0], x[0]
        value = float(u @ e)
        ds["displacement"] = ((), value, {
            "long_name": f"displacement at the reference point along {np.round(e, 6).tolist()}",
            "units": "length", "reference_point": list(map(float, x))})
        refs = [float(r) for r in self.references]
        labels = list(self.reference_labels) or [f"reference {i}" for i in range(len(refs))]
        if refs:
            ds["displacement"].attrs.update(reference=refs[0], reference_source=labels[0])
            ds["relative_error"] = ((), abs(value - refs[0]) / abs(refs[0]), {
                "long_name": f"|displacement − ref| / |ref|, ref = {refs[0]} ({labels[0]})",
                "units": "1"})
            ds = ds.assign_coords(reference=("reference", labels, {
                "long_name": "published value", "units": "1"}))
            ds["reference_value"] = (("reference",), refs, {"long_name": "published value",
                                                            "units": "length"})
            ds["relative_error_vs"] = (("reference",),
                                       [abs(value - r) / abs(r) for r in refs],
                                       {"long_name": "relative error against each reference",
                                        "units": "1"})
            ctx.log.info("displacement %.8g; relative error %s", value, ", ".join(
                f"{lab}: {abs(value - r) / abs(r):.3e}" for lab, r in zip(labels, refs)))
        size = float(np.ptp(ds["position"].values, axis=0).max())
        umax = float(ds["max_displacement"])
        mag = self.magnification or (0.1 * size / umax if umax > 0 else 1.0)
        ds.attrs["magnification"] = mag
        triangles = getattr(physics, "surface_triangles", None)
        if triangles is not None:  # the report draws the surface, not dots
            ds["surface_triangle"] = (("triangle", "corner"), np.asarray(triangles(), np.int64), {
                "long_name": "triangles of the sampled surface (indices of points)",
                "units": "1"})
        ds.attrs["title"] = f"Kirchhoff–Love shell: {cloud.name}, {int(ds['dof'])} DOF"
        if self.write_vtp:
            from pointatlas_kit.paraview import units_system_of

            physics.export_vtp(ctx.run_dir / "shell.vtp", mag, units_system_of(ctx))
        return ds

    @staticmethod
    def report_figures(ds):
        from .shell_figures import deformed_picture

        return [("Deformed surface coloured by |u|, the undeformed one as grey edges "
                 f"(displacement drawn at {float(ds.attrs.get('magnification', 1.0)):.3g} "
                 "times its size)", deformed_picture(ds))]

    @staticmethod
    def report_sweep_figures(ds):
        from .shell_convergence import convergence_figures

        return convergence_figures(ds)
