"""Stokes flow round bodies of revolution against analytic values: drag, torque, squirmers,
reciprocal and small-amplitude strokes (issue 19's five experiments), or a user's stroke.

The study builds generating curves and surface motions from formulas
(:mod:`.meridian_motions`), hands them to the physics through its protocol only
(``physics.solve(ctx, shapes=…, velocities=…, times=…, motion=…)``, a Dataset back), and
compares with the references of :mod:`.squirming_sphere_theory` and the closed forms below.
``case``:

* ``drag``: a sphere (``aspect_ratio`` 1) or spheroid towed along its axis at ``speed``;
  reference 6πμaU (Stokes), or for a spheroid with equatorial radius a and polar semi-axis
  c = aspect·a, with e the eccentricity (Happel & Brenner 1965, §4-26; Chwang & Wu 1975):
  prolate F = 16πμ c e³ U / ((1 + e²) ln((1+e)/(1−e)) − 2e), oblate
  F = 8πμ a e³ U / (e √(1−e²) − (1 − 2e²) arcsin e).
* ``rotation``: a sphere spun about its axis, torque 8πμa³Ω.
* ``squirmer``: tangential slip B₁ sin θ + B₂ sin θ cos θ, free: U = 2B₁/3 and the exterior
  power of :func:`.squirming_sphere_theory.squirmer_power`.
* ``scallop``: a shape path traced forward then back at other rates
  (:func:`.meridian_motions.reciprocal_stroke`); net displacement and rotation against the
  displacement and rotation reached at the turning point.
* ``small_amplitude_stroke``: material displacement ε a Re[e^{−iωt}(Σ A_n P_n e_r +
  Σ B_n V_n e_θ)] for each ε of ``amplitudes``; the net displacement fitted as c₂ε² + c₄ε⁴
  against the second-order theory ε² Ū₂ T (:func:`.squirming_sphere_theory.
  second_order_mean_velocity`), and the log–log slope of |X(T)| over ε.
* ``stroke_file``: a user's stroke from ``stroke_file`` (.nc or .npz with ``times`` (K+1,),
  ``shapes`` (K+1, n, 2) and ``velocities`` (K+1, n, 3); see the README).

``relative_error`` is always |computed / reference − 1|. With ``refinement`` (element
counts) the drag, rotation and squirmer cases repeat the solve and report the error and its
observed rate in the element size, h ∝ 1/n_elements.
"""
from __future__ import annotations

from dataclasses import dataclass, field as dc_field
from typing import ClassVar, Dict, List

import numpy as np

from pointatlas.constraints import Each, Interval, Options, Types
from pointatlas.stores_config import stores_config

from . import meridian_motions as mm

CASES = ("drag", "rotation", "squirmer", "scallop", "small_amplitude_stroke", "stroke_file")


@dataclass
class StokesSwimmingSettings:
    case: str = "drag"
    radius: float = 1.0
    aspect_ratio: float = 1.0
    n_nodes: int = 257
    speed: float = 1.0
    angular_velocity: float = 1.0
    B1: float = 1.0
    B2: float = 0.0
    n_phases: int = 64
    amplitude: float = 0.3
    twist: float = 0.5
    warp: float = 0.5
    amplitudes: List[float] = dc_field(default_factory=lambda: [0.01, 0.02, 0.05, 0.1])
    radial_modes: Dict[str, List[float]] = dc_field(
        default_factory=lambda: {"2": [1.0, 0.0], "3": [0.0, 1.0]})
    tangential_modes: Dict[str, List[float]] = dc_field(default_factory=dict)
    stroke_file: str = ""
    refinement: List[int] = dc_field(default_factory=list)
    parameter_constraints: ClassVar[dict] = {
        "case": [Options(CASES)], "radius": [Interval(float, 0, None, closed="neither")],
        "aspect_ratio": [Interval(float, 0, None, closed="neither")],
        "n_nodes": [Interval(int, 9, None)], "speed": [Interval(float)],
        "angular_velocity": [Interval(float)], "B1": [Interval(float)], "B2": [Interval(float)],
        "n_phases": [Interval(int, 4, None)], "amplitude": [Interval(float, 0, 0.6)],
        "twist": [Interval(float)], "warp": [Interval(float, -0.9, 0.9)],
        "amplitudes": [Each(Interval(float, 0, 0.3, closed="neither"))],
        "radial_modes": [Types(dict)], "tangential_modes": [Types(dict)],
        "stroke_file": [Types(str)], "refinement": [Each(Interval(int, 4, None))]}


def spheroid_drag(mu: float, a: float, aspect: float, U: float) -> float:
    """Axial drag of a spheroid (equatorial radius a, polar semi-axis aspect·a) at speed U
    (module doc); 6πμaU at aspect 1."""
    c = aspect * a
    if abs(aspect - 1.0) < 1e-12:
        return 6.0 * np.pi * mu * a * U
    if aspect > 1.0:
        e = np.sqrt(1.0 - (a / c) ** 2)
        return 16.0 * np.pi * mu * c * e ** 3 * U / ((1 + e * e) * np.log((1 + e) / (1 - e))
                                                      - 2 * e)
    e = np.sqrt(1.0 - (c / a) ** 2)
    return 8.0 * np.pi * mu * a * e ** 3 * U / (e * np.sqrt(1 - e * e)
                                                 - (1 - 2 * e * e) * np.arcsin(e))


def _modes(d: dict) -> dict:
    from pointatlas.errors import ConfigError

    out = {}
    for k, v in d.items():
        try:
            n, (re, im) = int(k), v
        except (TypeError, ValueError):
            raise ConfigError(f"a mode is written n: [real, imaginary] with n ≥ 1, e.g. "
                              f"study.radial_modes={{'2': [1, 0]}}; got {k}: {v}.") from None
        if n < 1:
            raise ConfigError(f"mode {n}: modes start at n = 1.")
        out[n] = complex(float(re), float(im))
    return out


def _scalar(ds, name, value, long_name, units="1"):
    ds[name] = ((), float(value), {"long_name": long_name, "units": units})


@stores_config
class StokesSwimming:
    """Drag, torque and swimming of bodies of revolution against analytic values."""

    Config = StokesSwimmingSettings
    description: ClassVar[str] = ("Axisymmetric Stokes flow (physics=stokes_axisymmetric): "
                                  "drag, torque, squirmer, scallop and small-amplitude strokes "
                                  "against analytic values, or a user's stroke.")

    # ---------------------------------------------------------------- single shapes
    def _rigid(self, ctx, physics, case):
        from pointatlas.errors import ConfigError

        if case == "rotation" and abs(self.aspect_ratio - 1.0) > 1e-12:
            raise ConfigError("study.case=rotation has its reference for a sphere only; set "
                              "study.aspect_ratio=1.")
        nodes = mm.spheroid(self.radius, self.aspect_ratio, self.n_nodes)
        if case == "drag":
            v = mm.translation(nodes, self.speed)
        else:
            v = mm.rotation(nodes, self.angular_velocity)
        return physics.solve(ctx, shapes=nodes, velocities=v, motion="prescribed")

    def _single(self, ctx, physics):
        mu = float(physics.viscosity)
        a = self.radius
        if self.case == "drag":
            ds = self._rigid(ctx, physics, "drag")
            value = float(ds["axial_force"][0])
            ref = spheroid_drag(mu, a, self.aspect_ratio, self.speed)
            names = ("drag", "drag_reference", "axial force on the fluid of the towed body",
                     "viscosity * length^2 / time")
        elif self.case == "rotation":
            ds = self._rigid(ctx, physics, "rotation")
            value = float(ds["axial_torque"][0])
            ref = 8.0 * np.pi * mu * a ** 3 * self.angular_velocity
            names = ("torque", "torque_reference", "axial torque on the fluid of the spun "
                     "sphere", "viscosity * length^3 / time")
        else:
            from .squirming_sphere_theory import squirmer_power, squirmer_speed

            nodes, v = mm.squirmer_slip(a, self.n_nodes, self.B1, self.B2)
            ds = physics.solve(ctx, shapes=nodes, velocities=v, motion="free")
            value = float(ds["translation_velocity"][0])
            ref = squirmer_speed(self.B1, self.B2)
            names = ("swimming_speed", "swimming_speed_reference", "swimming speed V_c of "
                     "the free squirmer", "length / time")
            P, Pref = float(ds["power_out"][0]), squirmer_power(self.B1, self.B2, mu, a)
            _scalar(ds, "power", P, "power into the exterior fluid", "viscosity * length^3 "
                    "/ time^2")
            _scalar(ds, "power_reference", Pref, "Blake's squirmer dissipation (16π/3) μ a "
                    "(B₁² + B₂²/2)", "viscosity * length^3 / time^2")
            _scalar(ds, "power_relative_error", abs(P / Pref - 1.0), "|power / reference − 1|")
        _scalar(ds, names[0], value, names[2], names[3])
        _scalar(ds, names[1], ref, names[2] + " (analytic)", names[3])
        _scalar(ds, "relative_error", abs(value / ref - 1.0), f"|{names[0]} / reference − 1|")
        ctx.log.info("%s: %s = %.10g against %.10g (relative error %.3e) at %d elements",
                     self.case, names[0], value, ref, abs(value / ref - 1.0),
                     int(ds["n_elements"]))
        return ds, names[0]

    def _refinement(self, ctx, ds, metric):
        rows = []
        for n in self.refinement:
            with ctx.timed(f"solve_{n}"):
                d, _ = self._single(ctx, ctx.plugin("physics", n_elements=n))
            rows.append((n, float(d["relative_error"])))
        R = np.array(rows, float)
        with np.errstate(divide="ignore", invalid="ignore"):
            rate = np.log(R[:-1, 1] / R[1:, 1]) / np.log(R[1:, 0] / R[:-1, 0])
        ds = ds.assign_coords(refinement=("refinement", np.arange(len(R)), {
            "long_name": "refinement level", "units": "1"}))
        ds["refinement_n_elements"] = (("refinement",), R[:, 0].astype(int), {
            "long_name": "boundary elements", "units": "1"})
        ds["refinement_error"] = (("refinement",), R[:, 1], {
            "long_name": f"|{metric} / reference − 1|", "units": "1"})
        ds["refinement_rate"] = (("refinement",), np.append(np.nan, rate), {
            "long_name": "observed error rate in h ∝ 1/n_elements", "units": "1"})
        for n, e in rows:
            ctx.log.info("refinement: %d elements, relative error %.3e", n, e)
        return ds

    # ---------------------------------------------------------------- strokes
    def _scallop(self, ctx, physics):
        t, X, V, s = mm.reciprocal_stroke(self.radius, self.n_nodes, self.n_phases,
                                          self.amplitude, self.twist, self.warp)
        ds = physics.solve(ctx, shapes=X, velocities=V, times=t, motion="free")
        turn = int(np.argmax(s))
        half_x = float(ds["position"][turn])
        half_r = float(ds["angle"][turn]) / (2 * np.pi)
        net_x, net_r = float(ds["net_displacement"]), float(ds["net_rotation"])
        _scalar(ds, "half_stroke_displacement", half_x, "displacement at the turning point of "
                "the shape path", "length")
        _scalar(ds, "half_stroke_rotation", half_r, "rotation/2π at the turning point")
        _scalar(ds, "displacement_ratio", abs(net_x / half_x), "|net / half-stroke "
                "displacement| (0 by the scallop theorem)")
        _scalar(ds, "rotation_ratio", abs(net_r / half_r), "|net / half-stroke rotation| "
                "(0 by the scallop theorem)")
        ctx.log.info("scallop: net displacement %.3e, half-stroke %.5g (ratio %.2e); net "
                     "rotation %.3e, half-stroke %.5g (ratio %.2e)", net_x, half_x,
                     abs(net_x / half_x), net_r, half_r, abs(net_r / half_r))
        return ds

    def _small_amplitude(self, ctx, physics):
        from .squirming_sphere_theory import second_order_mean_velocity

        radial, tangential = _modes(self.radial_modes), _modes(self.tangential_modes)
        eps = np.array(sorted(self.amplitudes), float)
        net = []
        ds = None
        for e in eps:
            t, X, V = mm.small_amplitude_stroke(self.radius, self.n_nodes, self.n_phases, e,
                                                radial, tangential)
            with ctx.timed(f"stroke_{e:g}"):
                d = physics.solve(ctx, shapes=X, velocities=V, times=t, motion="free")
            net.append(float(d["net_displacement"]))
            ctx.log.info("ε = %g: net displacement per stroke %.6e", e, net[-1])
            ds = d                  # the per-phase variables: the stroke of the largest ε
        net = np.array(net)
        # the theory: mean velocity ε² Ū₂ (a ω) over T = 1 with ω = 2π
        theory = second_order_mean_velocity(radial, tangential, a=self.radius,
                                            omega=2 * np.pi)
        c2_theory = theory * 1.0
        if len(eps) >= 2:
            slope = np.polyfit(np.log(eps), np.log(np.abs(net)), 1)[0]
            c2, c4 = np.linalg.lstsq(np.column_stack([eps ** 2, eps ** 4]), net, rcond=None)[0]
        else:
            slope, c2 = np.nan, net[0] / eps[0] ** 2
        ds = ds.assign_coords(amplitude=("amplitude", eps, {"long_name": "stroke amplitude ε",
                                                             "units": "1"}))
        ds["amplitude_net_displacement"] = (("amplitude",), net, {
            "long_name": "net displacement per stroke at each ε", "units": "length"})
        ds["amplitude_theory"] = (("amplitude",), c2_theory * eps ** 2, {
            "long_name": "second-order theory ε² Ū₂ T", "units": "length"})
        _scalar(ds, "stroke_amplitude", eps[-1], "ε of the stroke whose samples are shown "
                "(the largest)")
        _scalar(ds, "amplitude_exponent", slope, "log–log slope of |X(T)| against ε")
        _scalar(ds, "second_order_coefficient", c2, "c₂ of the fit X(T) = c₂ε² + c₄ε⁴",
                "length")
        _scalar(ds, "second_order_coefficient_reference", c2_theory, "Ū₂ T of the "
                "second-order theory (Felderhof & Jones 1994; reciprocal theorem)", "length")
        _scalar(ds, "relative_error", abs(c2 / c2_theory - 1.0), "|c₂ / theory − 1|")
        ctx.log.info("small-amplitude stroke: exponent %.4f, c₂ = %.6e against %.6e "
                     "(relative error %.3e)", slope, c2, c2_theory, abs(c2 / c2_theory - 1))
        return ds

    def _stroke_file(self, ctx, physics):
        from .stroke_files import read_stroke

        t, X, V = read_stroke(self.stroke_file)
        return physics.solve(ctx, shapes=X, velocities=V, times=t, motion="free")

    # ---------------------------------------------------------------- run
    def run(self, ctx):
        from pointatlas.errors import ConfigError

        physics = ctx.plugin("physics")
        if not callable(getattr(physics, "solve", None)) or "viscosity" not in getattr(
                type(physics).Config, "__dataclass_fields__", {}):
            raise ConfigError(f"study=stokes_swimming needs a Stokes physics "
                              f"(physics=stokes_axisymmetric); physics="
                              f"{ctx.choices.get('physics')} is not one.")
        with ctx.timed("solve"):
            if self.case in ("drag", "rotation", "squirmer"):
                ds, metric = self._single(ctx, physics)
                if self.refinement:
                    ds = self._refinement(ctx, ds, metric)
            elif self.case == "scallop":
                ds = self._scallop(ctx, physics)
            elif self.case == "small_amplitude_stroke":
                ds = self._small_amplitude(ctx, physics)
            else:
                ds = self._stroke_file(ctx, physics)
        if self.refinement and self.case not in ("drag", "rotation", "squirmer"):
            ctx.log.warning("study.refinement is used by the drag, rotation and squirmer "
                            "cases only; ignored for case=%s", self.case)
        ds.attrs["title"] = f"Stokes flow: {self.case}"
        return ds

    @staticmethod
    def report_figures(ds):
        from .stokes_figures import run_figures

        return run_figures(ds)

    @staticmethod
    def report_sweep_figures(ds):
        from .stokes_figures import sweep_figures

        return sweep_figures(ds)
