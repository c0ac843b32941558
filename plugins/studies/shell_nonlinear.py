"""Geometrically nonlinear shell analysis along a load path (thesis §4.4, Paper 2 §4–5).

The ``kirchhoff_love`` plugin builds the atlas, loads and supports; this study follows the
load path (:mod:`pointatlas_solvers.path_following`) under ``control``:

- ``force``: the loads grow with λ (uniform steps, cut on failure);
- ``displacement``: the ``displacement`` supports' imposed values grow with λ, there are no
  loads, and ``load`` is the reaction of those supports along their imposed direction;
- ``arc_length``: Crisfield's arc length (:mod:`pointatlas_solvers.arc_length`)
  on loads and imposed displacements together, through limit points and snap-backs; with
  ``branch_switching`` it also leaves the path at simple bifurcations for the secondary
  branch (eigenvector injection, :mod:`pointatlas_solvers.branch_switching`);
- under ``force`` or ``displacement`` control with ``stable_path``, every increment is solved
  by descent on the energy, so it ends on a stable state: past a limit point or a
  bifurcation, the one the shell snaps to (``snapped``;
  :mod:`pointatlas_solvers.stable_equilibrium`);

and records, along a dim ``increment``: ``load_factor``, ``load`` (= load_factor × ``full_load``
under loads),
the monitored displacements (``monitor_variable`` with dims (increment, point), point named
by ``monitor_names``), the energy split, Newton iterations and the displacement field. After
every converged increment ``increments.nc`` in the run directory is rewritten durably, with
the path follower's state (:mod:`.increment_store`), so an interrupted run keeps every
converged increment; ``resume_from`` (the run directory of an interrupted run with the same
settings) continues the path exactly where it stopped, and its results hold every increment,
the earlier ones included, as an uninterrupted run's would. Published curves
(``reference_load_factors`` × ``reference_values``, one row per monitored point) give
``max_relative_error``.

With ``write_vtp`` (default) every converged increment k is also written for ParaView as
``snapshots/increment_NNNN.vtp`` (surface triangles, ``u``, ``u_magnitude``,
``energy_density``, ``bending_fraction``, with units; :mod:`pointatlas_kit.paraview`), and
``shell_nonlinear.pvd`` is rewritten to list increments 0…k (timestep λ; the increment index
under arc length): after a kill it lists exactly the increments whose files are complete,
and a resumed run writes those of ``resume_from`` first, so its files are the uninterrupted
run's. Warp By Vector with ``u`` draws the deformed shape (scale ``study.magnification``, 1
when 0).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar, List, Optional

import numpy as np

from pointatlas.stores_config import stores_config

from .shell import ShellStudySettings


@dataclass
class ShellPathSettings(ShellStudySettings):
    n_increments: int = 20
    max_load_factor: float = 1.0
    max_newton: int = 15
    newton_tol: float = 1e-8
    full_load: float = 1.0              # force at load factor 1 (reported as ``load``)
    control: str = "force"              # force | displacement | arc_length
    lbfgs_iterations: int = 0           # L-BFGS iterations before Newton in each increment
    lbfgs_tol: float = 1.0e-2           # ... until |∇Π| ≤ lbfgs_tol·|load|
    line_search: bool = False           # Armijo backtracking in Newton (see increment)
    max_increments: int = 400           # arc length: increments before giving up
    branch_switching: bool = False      # arc length: leave the path at simple bifurcations
    max_branch_switches: int = 3        # ... at most this many times
    stable_path: bool = False           # force/displacement control by descent on the
                                        # energy: stable states only, snaps past instabilities
    monitor_points: List[float] = field(default_factory=list)       # x, y, z per point
    monitor_directions: List[float] = field(default_factory=list)   # unit vector per point
    monitor_names: List[str] = field(default_factory=list)
    monitor_variable: str = "displacement_at"
    monitor_magnitude: bool = False     # report |u·e| (magnitudes) instead of u·e
    reference_load_factors: List[float] = field(default_factory=list)
    reference_values: List[float] = field(default_factory=list)     # row per monitored point
    reference_label: str = ""
    reference_split_level: Optional[float] = None   # errors also before/after this level
    monitor_variables: List[str] = field(default_factory=list)  # also one variable per point
    resume_from: Optional[str] = None


@stores_config
class ShellNonlinearStudy:
    """Follow a shell's load path with Newton and step cutting; monitor points; compare."""

    Config = ShellPathSettings
    description: ClassVar[str] = (
        "Geometrically nonlinear Kirchhoff–Love shell along a load path (force, displacement "
        "or arc-length control; L-BFGS + Newton with line search; step cutting; stability by "
        "pivot signs); load–deflection curves.")

    def atlas_settings(self, ctx=None):
        """The run's ``atlas.*`` settings (old ``study.*`` spellings honoured, deprecated)."""
        from pointatlas_atlas.plugin import study_atlas_settings

        from .shell import SHELL_MARKERS_PER_PATCH

        return study_atlas_settings(ctx, self, markers_per_patch=SHELL_MARKERS_PER_PATCH)

    def check_config(self) -> None:
        """Start-up checks that need no model (run before the run directory is made): the
        atlas settings, the path's numbers, and ``resume_from`` naming a run directory that
        holds increments.nc (its contents are checked when the run reads it)."""
        import math

        from pointatlas.errors import ConfigError

        self.atlas_settings().check()
        for name, positive in (("max_load_factor", True), ("newton_tol", True),
                               ("lbfgs_tol", True), ("full_load", False),
                               ("magnification", False)):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and (v > 0 or not positive)):
                raise ConfigError(f"study.{name} = {v!r} is invalid; it must be a finite number"
                                  f"{' > 0' if positive else ''}.")
        if self.resume_from:
            from .increment_store import check_resume_dir

            check_resume_dir(self.resume_from)

    def _monitors(self):
        from pointatlas.errors import ConfigError

        P = np.asarray(self.monitor_points, dtype=float).reshape(-1, 3)
        E = np.asarray(self.monitor_directions, dtype=float).reshape(-1, 3)
        names = list(self.monitor_names)
        if not (len(P) == len(E) == len(names)) or len(P) == 0:
            raise ConfigError("study.monitor_points, monitor_directions (3 numbers per point) "
                              "and monitor_names must describe the same ≥ 1 points.")
        if self.monitor_variables and len(self.monitor_variables) != len(names):
            raise ConfigError(f"study.monitor_variables has {len(self.monitor_variables)} "
                              f"names for {len(names)} monitored points: give one per point "
                              "or none.")
        return P, E / np.linalg.norm(E, axis=1)[:, None], names

    def run(self, ctx):
        from pointatlas_solvers.increment import PathSettings
        from pointatlas_solvers.path_following import follow_path

        from pointatlas.errors import ConfigError

        from pointatlas.run_files import remove_partial_files

        from .increment_store import read_increments, run_settings

        if ctx.plugin_name("physics") != "kirchhoff_love":
            raise ConfigError("study=shell_nonlinear needs physics=kirchhoff_love.")
        P, E, names = self._monitors()
        remove_partial_files(ctx.run_dir)  # the study may run outside run_study (tests)
        settings = run_settings(ctx)
        # checked before the model is built: a wrong resume_from fails in a moment
        history = read_increments(self.resume_from, settings) if self.resume_from else []
        atlas_settings = self.atlas_settings(ctx)
        atlas_settings.check()
        with ctx.timed("source"):
            cloud = ctx.plugin("source").load(ctx.rng("source"))
        physics = ctx.plugin("physics")
        with ctx.timed("model"):
            model = physics.path_problem(ctx, cloud=cloud, atlas_settings=atlas_settings)
        start = self._resume(history, model) if history else None
        records = list(history)
        probe = model.probe(P, E)        # projections once, not per increment
        fields = model.point_fields()    # u and energy density at the sampled points
        values = [probe(r.U) for r in records]
        self._fields = [fields(r.U) for r in records]
        self._points = model.points
        self._check_control(model)
        path = PathSettings(self.n_increments, self.max_load_factor, self.max_newton,
                            self.newton_tol, control="arc_length" if self.control ==
                            "arc_length" else "load", lbfgs_iterations=self.lbfgs_iterations,
                            lbfgs_tol=self.lbfgs_tol, line_search=self.line_search,
                            max_increments=self.max_increments,
                            branch_switching=self.branch_switching,
                            max_branch_switches=self.max_branch_switches,
                            stable_path=self.stable_path,
                            levels=tuple(self.reference_load_factors))
        self._imposed = model.imposed
        self._has_loads = model.has_loads
        series = self._series(ctx, physics, model, records)

        total = (f"at most {self.max_increments}" if self.control == "arc_length"
                 else f"{self.n_increments} planned, more if a step is cut")
        clock = {}

        def eta(load_factor: float) -> str:
            """Time left from the λ progress since the first increment (JIT excluded)."""
            import time

            from pointatlas.progress import format_seconds

            now, frac = time.perf_counter(), load_factor / self.max_load_factor
            if "t" not in clock:
                clock.update(t=now, frac=frac)
                return "ETA ?"
            done = frac - clock["frac"]
            if done <= 0 or frac >= 1:
                return "ETA ?" if frac < 1 else "ETA 0s"
            return f"ETA {format_seconds((now - clock['t']) / done * (1 - frac))}"

        def keep(inc):
            records.append(inc)
            values.append(probe(inc.U))
            self._fields.append(fields(inc.U))
            ctx.log.info("increment %d (%s): λ = %.5g of %.5g, %d Newton iterations, %s, %s; %s",
                         len(records), total, inc.load_factor, self.max_load_factor,
                         inc.iterations,
                         "stable" if inc.stable else "UNSTABLE", eta(inc.load_factor),
                         ", ".join(f"{n} = {v:.5g}" for n, v in zip(names, values[-1])))
            self._write(ctx.run_dir / "increments.nc", model, records, values, names, settings)
            if series is not None:
                self._snapshot(series, records, len(records) - 1)

        from pointatlas_solvers.increment import PathFollowingError

        stopped = ""
        with ctx.timed("path"):
            try:
                follow_path(model.problem, path, keep, ctx.log, start=start)
            except PathFollowingError as exc:
                stopped = str(exc)
                ctx.log.error("%s", exc)
        ds = self._dataset(model, records, values, names)
        ds.attrs["stopped"] = stopped or "completed the load path"
        ds.attrs["linear_solver"] = model.linear_solver
        warning = model.warning()  # failed patches, kept by the user's choice
        if warning:
            ds.attrs["warnings"] = warning
        return ds

    def _check_control(self, model) -> None:
        """The control is known and has something to apply (loads or imposed values)."""
        from pointatlas.errors import ConfigError

        controls = ("force", "displacement", "arc_length")
        if self.control not in controls:
            raise ConfigError(f"study.control = {self.control!r} is unknown; use one of "
                              f"{controls}.")
        if self.branch_switching and self.control != "arc_length":
            raise ConfigError("study.branch_switching=true needs study.control=arc_length (the "
                              "secondary branch is followed by arc length).")
        if self.stable_path and self.control == "arc_length":
            raise ConfigError("study.stable_path=true needs study.control=force or displacement "
                              "(arc length follows the unstable branches on purpose; use "
                              "branch_switching there).")
        imposed = bool(model.imposed)
        if self.control == "displacement":
            if not imposed:
                raise ConfigError("study.control=displacement needs a support of kind "
                                  "'displacement' (its value grows with the load factor).")
            if model.has_loads:
                raise ConfigError("study.control=displacement applies no loads, but "
                                  "physics.loads is not empty: remove the loads, or use "
                                  "study.control=force or arc_length to scale both.")
        elif not model.has_loads and not imposed:
            raise ConfigError(f"study.control={self.control} but there is nothing to apply: "
                              "give physics.loads or a 'displacement' support.")

    def _load(self, lam, reactions):
        """(load, long_name): λ·full_load under loads; otherwise the reaction of the
        'displacement' supports along their imposed direction (force)."""
        if self._has_loads or not self._imposed or reactions is None:
            return lam * self.full_load, "applied force λ·full_load"
        total = 0.0
        for k, value in self._imposed:
            e = value / max(np.linalg.norm(value), 1e-300)
            total += float(reactions[k] @ e)
        return total, ("reaction force of the imposed-displacement supports along their "
                       "imposed direction")

    def _resume(self, history, model):
        """Where the path goes on from the increments of ``resume_from``, after checking that
        they fit this model (same settings give the same model; this guards the file)."""
        from pointatlas_solvers.path_state import PathStart

        from pointatlas.errors import InputError

        state = history[-1].state
        if (history[-1].U.size != model.n_dofs or state.U.size != model.n_dofs
                or state.mu.size != model.n_constraint_rows):
            raise InputError(f"study.resume_from={self.resume_from}: its increments hold "
                             f"{history[-1].U.size} DOF and {state.mu.size} support rows "
                             f"but this model has {model.n_dofs} and "
                             f"{model.n_constraint_rows}: resume with the same source and "
                             "settings, or rerun without study.resume_from.")
        return PathStart(history, state)

    def _dataset(self, model, records, values, names):
        from .shell_path_results import path_dataset

        pairs = [self._load(r.load_factor, r.reactions) for r in records]
        return path_dataset(self, model.n_dofs, self._points, records, values, names,
                            self._fields, pairs)

    def _series(self, ctx, physics, model, records):
        """With ``write_vtp``: the ParaView series (``snapshots/increment_NNNN.vtp`` and
        ``shell_nonlinear.pvd``, :class:`pointatlas_kit.paraview.SnapshotSeries`) with the
        increments of ``records`` already written (those of ``resume_from``: a resumed run
        has the files of the uninterrupted one); None without."""
        if not self.write_vtp:
            return None
        from pointatlas_kit.paraview import SnapshotSeries, units_system_of

        series = SnapshotSeries(ctx.run_dir / "shell_nonlinear.pvd", ctx.run_dir / "snapshots")
        self._units_system = units_system_of(ctx)
        self._triangles = physics.surface_triangles(model)
        for k in range(len(records)):
            self._snapshot(series, records, k, publish=k == len(records) - 1)
        return series

    def _snapshot(self, series, records, k: int, publish: bool = True) -> None:
        """Increment ``k``'s .vtp (surface triangles; ``u``, ``u_magnitude``,
        ``energy_density``, ``bending_fraction`` with units; field values ``load_factor``,
        ``load``, ``magnification``), then the .pvd listing increments 0…k, timestep = the
        load factor λ (the increment index under arc length, where λ may go back)."""
        from pointatlas_kit.paraview import Array, write_vtp

        u, w = self._fields[k]
        r = records[k]
        load, what = self._load(r.load_factor, r.reactions)
        total = w[:, 2]
        write_vtp(series.path(k), self._points, self._triangles, {
            "u": Array(u, "length", "displacement u(x_a) at the sampled points"),
            "u_magnitude": Array(np.linalg.norm(u, axis=1), "length", "|u|"),
            "energy_density": Array(total, "energy/length²", "strain energy per unit "
                                    "reference area (membrane + bending)"),
            "bending_fraction": Array(w[:, 1] / np.where(total > 0, total, 1.0), "1",
                                      "bending share of the energy density")}, {
            "load_factor": Array(float(r.load_factor), "1", "load factor λ"),
            "load": Array(float(load), "force", what),
            "magnification": Array(float(self.magnification or 1.0), "1",
                                   "scale factor of u for Warp By Vector")},
            self._units_system)
        if publish:
            lam = [float(x.load_factor) for x in records[:k + 1]]
            by_lambda = self.control != "arc_length" and bool(np.all(np.diff(lam) > 0))
            series.publish(lam if by_lambda else list(range(k + 1)))

    def _write(self, path: Path, model, records, values, names, settings):
        """increments.nc with all converged increments and the path state (durably)."""
        from .increment_store import write_increments

        write_increments(path, self._dataset(model, records, values, names), records, settings)

    @staticmethod
    def report_figures(ds):
        from .shell_path_results import path_figures

        return path_figures(ds)

