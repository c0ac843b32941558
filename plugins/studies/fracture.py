"""A fracturing shell under imposed displacement: increments, crack jumps, energies, resume.

The study asks the physics for its built problem (``physics.fracture_path``: the protocol of
:class:`pointatlas_physics.kirchhoff_love_fracture.staggered.StaggeredProblem`, no physics
module imported) and follows the imposed-displacement factor t from 0 to ``max_factor`` in
``n_increments`` equal steps Δt. When the elastic energy drops by more than
``jump_fraction`` of its value within a step (a crack jumps), the step is rejected and
halved, down to Δt · ``min_step_fraction``, where the jump is accepted; a step whose
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
``staggered_iterations``, ``crack_length`` (fracture energy / (G_c h)), ``min_phase_field``,
and the fields ``phase_field`` and ``displacement`` at every sampled point; the run directory
gets ``snapshots/increment_NNNN.vtp`` (υ, u and the deformed points) of every increment.

With ``griffith_half_length`` a and ``griffith_width`` W (a plate of width W with a central
crack 2a pulled normal to it; ``griffith_model: quarter`` for the quarter x, y ≥ 0 with
symmetry edges, whose pulled edge is W/2 wide) the headline figures are ``peak_stress`` =
max reaction / (loaded width · h), the remote stress at the peak, against Griffith's critical stress in plane stress
with Feddersen's width correction,

    ``griffith_stress`` σ_c = √(E G_c / (π a)) · √(cos(π a / W)),

and ``relative_error`` = peak_stress / σ_c − 1 (E, G_c, h from the physics' ``material``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

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
    parameter_constraints: ClassVar[dict] = {
        "griffith_model": [Options(("full", "quarter"))],
        "griffith_half_length": [Interval(float, 0, None, closed="neither"), None],
        "griffith_width": [Interval(float, 0, None, closed="neither"), None],
        "n_increments": [Interval(int, 1, None)],
        "max_factor": [Interval(float, 0, None, closed="neither")],
        "jump_fraction": [Interval(float, 0, 1, closed="neither")],
        "min_step_fraction": [Interval(float, 0, 1, closed="right")],
        "resume_from": [Types(str), None]}


@stores_config
class FractureStudy:
    """Imposed-displacement path of a fracturing shell (module doc)."""

    Config = FractureStudySettings
    description: ClassVar[str] = ("Imposed-displacement path of a fracturing shell (physics="
                                  "kirchhoff_love_fracture): staggered increments refined at "
                                  "crack jumps, reaction and energies, resumable.")

    def check_config(self) -> None:
        if self.resume_from:
            from .increment_store import check_resume_dir

            check_resume_dir(self.resume_from)

    def run(self, ctx):
        from pointatlas.errors import ConfigError
        from pointatlas_atlas.plugin import study_atlas_settings
        from pointatlas_solvers.increment import PathFollowingError

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
        with ctx.timed("build"):
            problem = physics.fracture_path(ctx, cloud=cloud, atlas_settings=a)
        if history is not None:
            records, step = store.restore(history, problem, self.resume_from)
        else:
            with ctx.timed("initial"):
                records, step = [problem.initial_state()], 1.0 / self.n_increments
        path = ctx.run_dir / store.NAME
        full = self.max_factor / self.n_increments
        rejected, stopped = False, ""
        while records[-1].factor < self.max_factor * (1 - 1e-12):
            prev = records[-1]
            dt = min(step * self.max_factor, self.max_factor - prev.factor)
            smallest = full * self.min_step_fraction * (1 + 1e-9)
            try:
                with ctx.timed("increments"):
                    new = problem.increment(prev, prev.factor + dt)
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
            store.write(path, problem, records, step, settings)
        ds = store.dataset(problem, records)
        self._snapshots(ctx.run_dir / "snapshots", problem, records)
        ds.attrs["title"] = f"phase-field fracture of {cloud.name}"
        ds.attrs["stopped"] = stopped or "completed the path"
        if stopped:   # the converged increments are kept; the run says it did not finish
            ds.attrs["warnings"] = f"the path stopped before study.max_factor: {stopped}"
        if self.griffith_half_length is not None:
            ds = self._griffith(ds, problem.material())
        return ds

    @staticmethod
    def _snapshots(folder, problem, records):
        """``snapshots/increment_NNNN.vtp`` of every increment (υ, u, deformed shape), written
        from the records at the end, so a resumed run has them all too."""
        folder.mkdir(parents=True, exist_ok=True)
        for k, r in enumerate(records):
            problem.write_vtp(r, folder / f"increment_{k:04d}.vtp")

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
