"""A fracturing shell under imposed displacement: increments, crack jumps, energies, resume.

The study asks the physics for its built problem (``physics.fracture_path``: the protocol of
:class:`pointatlas_physics.kirchhoff_love_fracture.staggered.StaggeredProblem`, no physics
module imported) and follows the imposed-displacement factor t from 0 to ``max_factor`` in
``n_increments`` equal steps Δt. When the elastic energy drops by more than
``jump_fraction`` of its value within a step (a crack jumps), the step is rejected and
halved, down to Δt · ``min_step_fraction``, where the jump is accepted (above the smallest
step the physics is given that energy floor and stops the staggered iteration at the first
iterate below it, ``increment(..., jump_floor=)``, instead of converging a step that is
thrown away); a step whose
staggered iteration does not converge (it crawls at a jump) is halved too, and at the
smallest step the path stops there: the converged increments are the results, flagged in
``warnings`` and ``stopped`` (the run ends ``completed_with_warnings``). After a step
accepted at the first try without a jump the step doubles again, back to Δt at most.

After every accepted increment ``increments.nc`` in the run directory is rewritten durably
(:mod:`.fracture_increments`); ``resume_from`` (an interrupted run's directory, with the same
settings) continues from its last increment and gives the results of the run that was never
stopped. Results along ``increment``: ``imposed_displacement``, ``reaction``,
``elastic_energy``, ``fracture_energy``, ``external_work`` (∫ reaction d(imposed
displacement) by the trapezoidal rule, plus the work of dead loads t Fᵀu),
``staggered_iterations``, ``monolithic_iterations`` (0: solved by the staggered scheme),
``negative_modes`` (of the displacement step's tangent), ``crack_length`` (fracture energy
/ (G_c h)),
``min_phase_field_away`` (min υ at the points away from the pre-cracks,
``away_from_precracks``: outside the pre-cracks' own bands at increment 0, as the physics
defines them, ``problem.away_from_precracks``; every point without pre-crack), and
the fields ``phase_field`` and ``displacement`` at every sampled point; the run directory
gets ``snapshots/increment_NNNN.vtp`` (the surface's triangles, υ, u and the deformed points,
with units; :mod:`pointatlas_kit.paraview`) of every increment and ``fracture.pvd``, the
series ParaView animates (timestep = t).

With ``griffith_half_length`` a and ``griffith_width`` W (a plate of width W with a central
crack 2a pulled normal to it; ``griffith_model: quarter`` for the quarter x, y ≥ 0 with
symmetry edges, whose pulled edge is W/2 wide) the headline figures are ``peak_stress`` =
max reaction / (loaded width · h), the remote stress at the peak, against Griffith's critical stress in plane stress
with Feddersen's width correction,

    ``griffith_stress`` σ_c = √(E G_c / (π a)) · √(cos(π a / W)),

and ``relative_error`` = peak_stress / σ_c − 1 (E, G_c, h from the physics' ``material``).

The 0-d ``min_phase_field`` is ``min_phase_field_away`` at the last increment: no crack grew
away from the pre-cracks while it stays near 1. With ``contrast_split`` ('none' or 'amor') the
same path is followed again with the physics' energy split replaced (``problem.with_split``,
the same atlas), its figures stored as ``contrast_…`` along ``contrast_increment`` (and
``contrast_phase_field`` at the last increment): the compression check compares the two. A
resumed run recomputes the contrast path from its start (it is not in ``increments.nc``;
deterministic, so the results are those of an uninterrupted run).

``nucleation_displacement`` is the imposed displacement of the first increment whose min υ
away from the pre-cracks is below 0.1 (NaN: none on the path). With ``halves_plane``
[nx, ny, nz, d] the points are split by the plane (e.g. the neutral axis of a bent strip):
``min_phase_field_above`` / ``_below`` along ``increment`` and
``other_side_min_phase_field``, the min υ on the other side when one side first nucleates
(near 1: the crack starts on one side only). With ``mirror_plane``: ``symmetry_defect``
(:mod:`.fracture_symmetry`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, List, Optional

import numpy as np

from pointatlas.constraints import Interval, Options, Types
from pointatlas.stores_config import stores_config


@dataclass
class FractureStudySettings:
    n_increments: int = 20
    max_factor: float = 1.0
    jump_fraction: float = 0.1
    min_step_fraction: float = 1.0 / 64
    resume_from: Optional[str] = None
    griffith_half_length: Optional[float] = None
    griffith_width: Optional[float] = None
    griffith_model: str = "full"
    contrast_split: Optional[str] = None
    halves_plane: Optional[List[float]] = None
    mirror_plane: Optional[List[float]] = None
    parameter_constraints: ClassVar[dict] = {
        "griffith_model": [Options(("full", "quarter"))],
        "contrast_split": [Options(("none", "amor")), None],
        "griffith_half_length": [Interval(float, 0, None, closed="neither"), None],
        "griffith_width": [Interval(float, 0, None, closed="neither"), None],
        "n_increments": [Interval(int, 1, None)],
        "max_factor": [Interval(float, 0, None, closed="neither")],
        "jump_fraction": [Interval(float, 0, 1, closed="neither")],
        "min_step_fraction": [Interval(float, 0, 1, closed="right")],
        "resume_from": [Types(str), None]}


HALVES = ("min_phase_field_above", "min_phase_field_below", "other_side_min_phase_field",
          "other_side_min_phase_field_before")


def halves(ds, plane):
    """``min_phase_field_above`` / ``_below`` along ``increment`` (min υ away from the
    pre-cracks, ``away_from_precracks``, on each side n·x ≷ d of ``plane``) and
    ``other_side_min_phase_field``: at the first increment where one side has nucleated
    (< 0.1), the min υ on the other side (NaN if neither has): near 1 when the crack starts
    on one side only. A crack that runs through both sides within that increment (an
    unstable jump) leaves both low; ``other_side_min_phase_field_before`` is then the
    telling figure: the min υ on the side that is less damaged at the nucleating increment
    (the other side), at the increment before it."""
    from .fracture_increments import NUCLEATED
    from .fracture_symmetry import plane_offset

    p = np.asarray(plane, dtype=float).ravel()
    side, _ = plane_offset(ds["position"].values, p)
    v = ds["phase_field"].values
    away = ds["away_from_precracks"].values.astype(bool)
    out = {}
    for name, mask in (("above", away & (side > 0)), ("below", away & (side < 0))):
        out[name] = v[:, mask].min(axis=1) if mask.any() else np.full(len(v), np.nan)
        ds[f"min_phase_field_{name}"] = (("increment",), out[name], {
            "units": "1", "long_name": f"min υ away from the pre-cracks {name} the plane "
                                       f"{list(map(float, p))} (n·x {'>' if name == 'above' else '<'} d)"})
    hit = np.flatnonzero(np.fmin(out["above"], out["below"]) < NUCLEATED)
    other = before = float("nan")
    if hit.size:
        k = hit[0]
        name = "below" if out["above"][k] < out["below"][k] else "above"
        other = float(out[name][k])
        before = float(out[name][k - 1]) if k > 0 else float("nan")
    ds["other_side_min_phase_field"] = ((), other, {
        "units": "1", "long_name": "min υ on the other side of the plane when one side first "
                                   "has min υ < 0.1"})
    ds["other_side_min_phase_field_before"] = ((), before, {
        "units": "1", "long_name": "min υ on that other side at the increment before"})
    return ds


@stores_config
class FractureStudy:
    """Imposed-displacement path of a fracturing shell (module doc)."""

    Config = FractureStudySettings
    description: ClassVar[str] = ("Imposed-displacement path of a fracturing shell (physics="
                                  "kirchhoff_love_fracture): staggered increments refined at "
                                  "crack jumps, reaction and energies, resumable.")

    def check_config(self) -> None:
        self.check_planes()
        if self.resume_from:
            from .increment_store import check_resume_dir

            check_resume_dir(self.resume_from)

    def run(self, ctx):
        from pointatlas.errors import ConfigError
        from pointatlas_atlas.plugin import study_atlas_settings
        from . import fracture_increments as store
        from .increment_store import run_settings

        physics = ctx.plugin("physics")
        if not callable(getattr(physics, "fracture_path", None)):
            raise ConfigError(f"study=fracture needs a fracture physics (physics="
                              f"kirchhoff_love_fracture); physics={ctx.choices.get('physics')}.")
        settings = run_settings(ctx)
        history = store.read(self.resume_from, settings) if self.resume_from else None
        a = study_atlas_settings(ctx, self)
        a.check()
        cloud = ctx.plugin("source").load(ctx.rng("source"))
        if self.mirror_plane is not None:      # refused before any work (fracture_symmetry)
            from .fracture_symmetry import mirror_index

            mirror_index(np.asarray(cloud.points, dtype=float), self.mirror_plane)
        with ctx.timed("build"):
            problem = physics.fracture_path(ctx, cloud=cloud, atlas_settings=a)
        if history is not None:
            records, step = store.restore(history, problem, self.resume_from)
        else:
            with ctx.timed("initial"):
                records, step = [problem.initial_state()], 1.0 / self.n_increments
        path = ctx.run_dir / store.NAME
        records, stopped = self._follow(
            ctx, problem, records, step,
            lambda recs, st: store.write(path, problem, recs, st, settings))
        ds = store.dataset(problem, records)
        self._snapshots(ctx, problem, records)
        ds.attrs["title"] = f"phase-field fracture of {cloud.name}"
        ds.attrs["stopped"] = stopped or "completed the path"
        warnings = [f"the path stopped before study.max_factor: {stopped}"] if stopped else []
        if self.halves_plane is not None:
            ds = halves(ds, self.halves_plane)
        if self.mirror_plane is not None:
            from .fracture_symmetry import symmetry_defect

            ds = symmetry_defect(ds, self.mirror_plane)
        if self.contrast_split is not None:
            ds, note = self._contrast(ctx, problem, ds)
            warnings += [note] if note else []
        if warnings:   # the converged increments are kept; the run says it did not finish
            ds.attrs["warnings"] = "; ".join(warnings)
        if self.griffith_half_length is not None:
            ds = self._griffith(ds, problem.material())
        return ds

    def _contrast(self, ctx, problem, ds):
        """The same path with the split ``contrast_split`` (module doc): its variables
        prefixed ``contrast_`` along ``contrast_increment``; (ds, warning or '')."""
        from . import fracture_increments as store

        other = problem.with_split(self.contrast_split)
        with ctx.timed("contrast"):
            records, stopped = self._follow(ctx, other, [other.initial_state()],
                                            1.0 / self.n_increments, None)
        c = store.dataset(other, records)
        keep = ["load_factor", "imposed_displacement", "reaction", "elastic_energy",
                "fracture_energy", "staggered_iterations", "min_phase_field_away",
                "min_phase_field", "nucleation_displacement"]
        if self.halves_plane is not None:
            c = halves(c, self.halves_plane)
            keep += list(HALVES)
        for name in keep:
            v = c[name].rename({"increment": "contrast_increment"}) if "increment" in \
                c[name].dims else c[name]
            ds[f"contrast_{name}"] = v.assign_attrs(
                long_name=f"{c[name].attrs['long_name']} (split {self.contrast_split})")
        ds["contrast_phase_field"] = (("point",), c["phase_field"].values[-1], {
            "units": "1", "long_name": f"phase field υ(x_a) at the last increment (split "
                                       f"{self.contrast_split})"})
        ds = ds.assign_coords(contrast_increment=("contrast_increment", np.arange(len(records)),
                                                  {"units": "1", "long_name": "increment of "
                                                   "the contrast path (0: initial state)"}))
        ds.attrs["contrast_split"] = self.contrast_split
        return ds, (f"the contrast path (split {self.contrast_split}) stopped before "
                    f"study.max_factor: {stopped}" if stopped else "")

    def check_planes(self):
        from .fracture_symmetry import check_plane

        for key in ("halves_plane", "mirror_plane"):
            if getattr(self, key) is not None:
                check_plane(getattr(self, key), key)

    def _follow(self, ctx, problem, records, step, write):
        """(records, stopped): the increments from ``records[-1]`` to ``max_factor`` (module
        doc), ``write(records, step)`` after each accepted one (None: not stored)."""
        from pointatlas_solvers.increment import PathFollowingError

        full = self.max_factor / self.n_increments
        rejected, stopped = False, ""
        while records[-1].factor < self.max_factor * (1 - 1e-12):
            prev = records[-1]
            dt = min(step * self.max_factor, self.max_factor - prev.factor)
            smallest = full * self.min_step_fraction * (1 + 1e-9)
            # below this elastic energy the increment is a jump, rejected unless the step is
            # already the smallest: the staggered iteration stops as soon as an iterate is
            floor = (1 - self.jump_fraction) * prev.energy["elastic"] \
                if dt > smallest and prev.energy["elastic"] > 0 else None
            try:
                with ctx.timed("increments"):
                    new = problem.increment(prev, prev.factor + dt, jump_floor=floor)
            except PathFollowingError as exc:   # e.g. the staggered iteration did not converge
                if dt > smallest:   # alternate minimisation crawls at a crack jump: cut
                    step /= 2
                    rejected = True
                    ctx.log.info("%s Step halved to %.3g.", exc, step * self.max_factor)
                    continue
                stopped = f"{exc} (at the smallest step, study.min_step_fraction)"
                ctx.log.error("path stopped: %s", stopped)
                break
            drop = (prev.energy["elastic"] - new.energy["elastic"]) / prev.energy["elastic"] \
                if prev.energy["elastic"] > 0 else 0.0
            if drop > self.jump_fraction and dt > smallest:
                step /= 2
                rejected = True
                ctx.log.info("elastic energy drops %.1f %% at t = %.6g: step halved to %.3g",
                             100 * drop, new.factor, step * self.max_factor)
                continue
            records.append(new)
            if drop <= self.jump_fraction and not rejected:
                step = min(2 * step, 1.0 / self.n_increments)
            rejected = False
            if write is not None:
                write(records, step)
        return records, stopped

    @staticmethod
    def report_figures(ds):
        from .fracture_figures import fracture_figures

        return fracture_figures(ds)

    @staticmethod
    def _snapshots(ctx, problem, records):
        """``snapshots/increment_NNNN.vtp`` of every increment (surface triangles, υ, u, the
        deformed shape) and ``fracture.pvd`` listing them with timestep = the factor t
        (ParaView animates the path), written from the records at the end, so a resumed run
        has them all too and the .pvd lists exactly the increments of the results."""
        from pointatlas_kit.paraview import Array, SnapshotSeries, units_system_of

        series = SnapshotSeries(ctx.run_dir / "fracture.pvd", ctx.run_dir / "snapshots")
        for k, r in enumerate(records):
            problem.write_vtp(r, series.path(k), field_data={
                "TimeValue": Array(float(r.factor), "1", "the factor t (the .pvd's timestep)")},
                units_system=units_system_of(ctx))
        series.publish([float(r.factor) for r in records])

    def _griffith(self, ds, material):
        """peak_stress, griffith_stress and relative_error (module doc)."""
        from pointatlas.errors import ConfigError

        if self.griffith_width is None:
            raise ConfigError("study.griffith_half_length needs study.griffith_width (W, the "
                              "plate's width across the crack).")
        a, W = float(self.griffith_half_length), float(self.griffith_width)
        E, Gc, h = (material[k] for k in ("young_modulus", "fracture_toughness", "thickness"))
        sigma_c = np.sqrt(E * Gc / (np.pi * a)) * np.sqrt(np.cos(np.pi * a / W))
        loaded = W / 2 if self.griffith_model == "quarter" else W
        peak = float(ds["reaction"].max()) / (loaded * h)
        stress = {"units": "force / length^2"}
        ds["peak_stress"] = ((), peak, {**stress, "long_name": "peak remote stress max "
                                                                "reaction / (loaded width h)"})
        ds["griffith_stress"] = ((), float(sigma_c), {
            **stress, "long_name": "Griffith σ_c = √(E G_c/(π a)) √(cos(π a/W)) (Feddersen)"})
        ds["relative_error"] = ((), peak / sigma_c - 1.0, {
            "units": "1", "long_name": "peak_stress / griffith_stress − 1"})
        return ds
