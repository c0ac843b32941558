"""Euglenid metaboly: from frames to the stroke, the pellicle kinematics and the swimming.

Thesis §6 and Arroyo, Heltai, Millán & DeSimone, PNAS 109 (2012) 17874 with its SI. Each stage
is a function on arrays in its own module; this study chains them and writes one Dataset:

1. frames from the ``source`` (``frames``: a video or a folder; ``synthetic_metaboly``: a
   rendered known stroke with its truth);
2. segmentation, sub-pixel contours, axis and axisymmetric profile per frame, dropped frames
   counted with their reason (:mod:`.metaboly_images`);
3. B-spline refit and arclength resampling, area, volume, reduced volume
   (:mod:`.metaboly_shapes`);
4. the ``embedder`` (Isomap, 30 neighbours) in 2-D (and 3-D for the report), cycles and the
   phase of every frame (:mod:`.metaboly_stroke`);
5. the smooth stroke: the ``approximant`` (LME) on ``n_bins`` periodic nodes over the phase,
   sampled at ``n_phases`` phases with its time derivative;
6. the pellicle kinematics: body coordinate, canonical reference pellicle, shear γ(λ, t),
   azimuthal displacement ψ and the material velocity (:mod:`.pellicle`);
7. the hydrodynamics over one stroke by the ``physics`` (``stokes_axisymmetric``, through its
   ``solve`` only): displacement in body lengths, rotation, powers, Lighthill efficiencies.

With a synthetic source, stages 5–7 are repeated on the true shapes at the aligned phases
(:mod:`.metaboly_truth`) and the errors written: ``shape_error``, ``period_error``,
``speed_error``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from pointatlas.constraints import Interval
from pointatlas.stores_config import stores_config

#: Arroyo et al. 2012, Table 1, Euglenid #3 (the row the euglenid-like stroke is shaped after)
PNAS_EUGLENID_3 = {"reduced_volume": (0.61, 0.63, 0.65), "shear_max": 3.0,
                   "displacement_per_stroke": 0.25, "net_rotation": 0.086,
                   "efficiency_out": 0.016, "efficiency_inner_outer": 0.0048}


@dataclass
class MetabolySettings:
    n_intervals: int = 24
    n_profile_points: int = 101
    n_bins: int = 40
    n_phases: int = 64
    n_material_nodes: int = 101
    max_asymmetry: float = 0.15
    max_area_deviation: float = 0.05
    parameter_constraints: ClassVar[dict] = {
        "n_intervals": [Interval(int, 20, 30)], "n_profile_points": [Interval(int, 21, None)],
        "n_bins": [Interval(int, 8, None)], "n_phases": [Interval(int, 8, None)],
        "n_material_nodes": [Interval(int, 21, None)],
        "max_asymmetry": [Interval(float, 0, None, closed="neither")],
        "max_area_deviation": [Interval(float, 0, None, closed="neither")]}


@stores_config
class Metaboly:
    """Frames of an axisymmetric cell → stroke, pellicle shear and swimming (module doc)."""

    Config = MetabolySettings
    description: ClassVar[str] = ("Euglenid metaboly from frames: segmentation, shape space "
                                  "(Isomap), LME stroke, pellicle shear, Stokes swimming.")

    def _stroke(self, ctx, shapes, dshapes, period):
        """Pellicle kinematics and hydrodynamics of one stroke sampled at n_phases phases."""
        from .pellicle import pellicle_kinematics

        kin = pellicle_kinematics(shapes, period, m=self.n_material_nodes, dshapes=dshapes,
                                  max_area_deviation=self.max_area_deviation)
        K = len(shapes)
        X = np.concatenate([kin.positions, kin.positions[:1]])
        V = np.concatenate([kin.velocities, kin.velocities[:1]])
        times = np.arange(K + 1) * period / K
        hyd = ctx.plugin("physics").solve(ctx, shapes=X, velocities=V, times=times)
        return kin, hyd

    def run(self, ctx):
        from pointatlas.errors import ConfigError

        from .metaboly_images import process_frames
        from .metaboly_report import build_dataset
        from .metaboly_shapes import descriptors
        from .metaboly_stroke import PeriodicLME, find_cycles

        with ctx.timed("frames"):
            seq = ctx.plugin("source").load(ctx.rng("source"))
        if not hasattr(seq, "frames"):
            raise ConfigError(f"study=metaboly needs a frame source (source=frames or "
                              f"source=synthetic_metaboly); source={ctx.choices.get('source')} "
                              f"gives points.")
        with ctx.timed("segmentation"):
            proc = process_frames(seq, n_profile=self.n_profile_points,
                                  max_asymmetry=self.max_asymmetry)
        ctx.log.info("%d of %d frames kept; dropped: %s", int(proc["kept"].sum()), seq.n_frames,
                     proc["counts"].get("dropped_by_reason", {}))
        self._check_axisymmetric(seq, proc)
        with ctx.timed("descriptors"):
            desc = descriptors(proc["curves"], self.n_intervals, self.n_profile_points)
        with ctx.timed("embedding"):
            Y = ctx.plugin("embedder").fit_transform(desc["vectors"])
            Y3 = ctx.plugin("embedder", n_components=3).fit_transform(desc["vectors"])
        cycles = find_cycles(Y, proc["times"])
        ctx.log.info("%d cycles (%s), mean period %.4g s", cycles.n_cycles,
                     "a loop" if cycles.loop else "a back-and-forth arc", cycles.period)
        with ctx.timed("parametrisation"):
            lme = PeriodicLME(ctx.plugin("approximant"), self.n_bins)
            lme.fit(cycles.phase, desc["vectors"])
            phases = np.arange(self.n_phases) / self.n_phases
            Xv, dXv = lme(phases)
            n = self.n_profile_points
            shapes, dshapes = Xv.reshape(-1, n, 2), dXv.reshape(-1, n, 2) / cycles.period
        with ctx.timed("kinematics_hydrodynamics"):
            kin, hyd = self._stroke(ctx, shapes, dshapes, cycles.period)
        truth = None
        if getattr(seq, "truth", None):
            with ctx.timed("truth"):
                truth = self._truth(ctx, seq, proc, shapes, phases, cycles)
        ds = build_dataset(seq, proc, desc, Y, Y3, cycles, phases, shapes, kin, hyd, truth)
        ds.attrs["title"] = f"metaboly of {seq.name}"
        if ds.attrs.get("warnings"):
            ctx.log.warning("%s", ds.attrs["warnings"])
        ctx.log.info("U = %.4g body lengths per stroke, Δθ/2π = %.4g, γ_max = %.3g, Eff_L out "
                     "%.3g %%, out+inn %.3g %%", float(ds["displacement_per_stroke"]),
                     float(ds["net_rotation"]), float(ds["shear_max"]),
                     100 * float(ds["efficiency_out"]), 100 * float(ds["efficiency_inner_outer"]))
        if truth is not None:
            ctx.log.info("against the truth: shape error %.3e (of the body length), period "
                         "error %.3e, speed error %.3e (U true %.4g)", float(ds["shape_error"]),
                         float(ds["period_error"]), float(ds["speed_error"]),
                         float(ds["displacement_per_stroke_reference"]))
        return ds

    def _check_axisymmetric(self, seq, proc):
        """InputError when most frames' silhouettes are not axisymmetric within
        ``max_asymmetry`` (their asymmetry listed per frame)."""
        from pointatlas.errors import InputError

        asym = np.asarray(proc["asymmetry"], float)
        bad = np.flatnonzero(asym > self.max_asymmetry)
        if len(bad) > 0.5 * seq.n_frames:
            order = np.argsort(seq.times, kind="stable")
            listed = ", ".join(f"{k}: {asym[i]:.3f}" for k, i in enumerate(order)
                               if asym[i] > self.max_asymmetry)
            listed = listed if len(listed) < 400 else listed[:400] + ", …"
            raise InputError(f"the cell is not axisymmetric within study.max_asymmetry="
                             f"{self.max_asymmetry:g} in {len(bad)} of {seq.n_frames} frames "
                             f"(asymmetry per frame, time order: {listed}). Check that the "
                             f"cell lies in the focal plane, or raise study.max_asymmetry.")

    def _truth(self, ctx, seq, proc, shapes, phases, cycles):
        from .metaboly_shapes import fit_curve
        from .metaboly_truth import align, shape_error, true_period

        fit = lambda c: fit_curve(c, self.n_intervals, self.n_profile_points)  # noqa: E731
        delta, flipped, true_shapes = align(shapes, seq.truth["shape"], phases, fit)
        T = true_period(seq.truth, float(cycles.starts[0]), float(cycles.starts[-1]))
        kin, hyd = self._stroke(ctx, true_shapes, None, T)
        U = float(hyd["net_displacement_body_lengths"])
        return {"shape_error": shape_error(shapes, true_shapes), "phase_offset": delta,
                "flipped": flipped, "period": T,
                "period_error": abs(cycles.period / T - 1.0),
                "displacement_per_stroke": U, "shear_max": kin.shear_max,
                "hydrodynamics": hyd}

    @staticmethod
    def report_figures(ds):
        from .metaboly_figures import run_figures

        return run_figures(ds)
