"""A pendulum reduced from noisy points of its configuration manifold (issue 21's
``rom_pendulum``; thesis §5 on the simplest slow manifold).

The full model: a mass ``mass`` on a circle of radius ``length`` under gravity ``gravity``
(x ∈ R², V(x) = m g (y + L), zero at the bottom). The snapshots: ``n_points`` positions
drawn uniformly in angle over ±``arc`` degrees from the bottom, with Gaussian noise of
``noise`` × L — a configuration manifold nobody hands the method. The ``embedder`` (Isomap,
d = 1) gives q; the ``approximant`` (LME) on ``n_bins`` binned nodes gives X(q)
(:mod:`pointatlas_reduction.slow_manifold`), the reduced Lagrangian ½ M̃(q) q̇² − Ṽ(q)
(:mod:`pointatlas_reduction.reduced_lagrangian`), tabulated once
(:mod:`pointatlas_reduction.tabulated_1d`) and integrated by the α = 0 variational
integrator from rest at ``amplitude`` degrees (its q by closest-point projection) for
``n_periods`` periods of ``steps_per_period`` steps. Reference period (exact pendulum):
T = 4 √(L/g) K(m = sin²(θ₀/2)). ``energy_drift``: max |E − E₀|/E₀ over the last tenth of
the run minus the same over the first tenth (zero when the error stays bounded).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from pointatlas.constraints import Interval
from pointatlas.stores_config import stores_config


@dataclass
class ReducedPendulumSettings:
    length: float = 1.0
    gravity: float = 1.0
    mass: float = 1.0
    n_points: int = 2000
    arc: float = 120.0
    noise: float = 0.001
    n_bins: int = 40
    amplitude: float = 90.0
    steps_per_period: int = 200
    n_periods: int = 10000
    save_every: int = 1
    parameter_constraints: ClassVar[dict] = {
        "length": [Interval(float, 0, None, closed="neither")],
        "gravity": [Interval(float, 0, None, closed="neither")],
        "mass": [Interval(float, 0, None, closed="neither")],
        "n_points": [Interval(int, 50, None)], "arc": [Interval(float, 10, 175)],
        "noise": [Interval(float, 0, 0.1)], "n_bins": [Interval(int, 4, None)],
        "amplitude": [Interval(float, 1, 170)], "steps_per_period": [Interval(int, 8, None)],
        "n_periods": [Interval(int, 2, None)], "save_every": [Interval(int, 1, None)]}


def exact_period(length: float, gravity: float, amplitude_deg: float) -> float:
    """T = 4 √(L/g) K(sin²(θ₀/2)) (scipy's ellipk takes m = k²)."""
    from scipy.special import ellipk

    return float(4.0 * np.sqrt(length / gravity)
                 * ellipk(np.sin(np.radians(amplitude_deg) / 2) ** 2))


def crossing_period(t, s) -> float:
    """Mean interval between upward zero crossings of s(t) (linear interpolation)."""
    i = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
    tc = t[i] - s[i] * (t[i + 1] - t[i]) / (s[i + 1] - s[i])
    return float(np.diff(tc).mean()) if len(tc) >= 2 else float("nan")


def _v(ds, name, value, long_name, units="1", dims=()):
    ds[name] = (dims, value, {"long_name": long_name, "units": units})


@stores_config
class ReducedPendulum:
    """A pendulum reduced by Isomap + LME from noisy points, against its exact period."""

    Config = ReducedPendulumSettings
    description: ClassVar[str] = ("A pendulum's slow manifold learnt from noisy points (Isomap "
                                  "+ LME), integrated by the α = 0 variational integrator.")

    def run(self, ctx):
        import xarray as xr

        from pointatlas.errors import ConfigError
        from pointatlas_reduction.reduced_lagrangian import ReducedLagrangian
        from pointatlas_reduction.slow_manifold import SlowManifold
        from pointatlas_reduction.tabulated_1d import Table1D, integrate_table

        if self.amplitude >= self.arc:
            raise ConfigError(f"study.amplitude={self.amplitude:g}° lies outside the sampled "
                              f"arc ±{self.arc:g}°: the reduced model knows nothing there. "
                              f"Raise study.arc or lower study.amplitude.")
        L, g, m = self.length, self.gravity, self.mass
        rng = ctx.rng("snapshots")
        th = np.radians(rng.uniform(-self.arc, self.arc, self.n_points))
        X = np.column_stack([L * np.sin(th), -L * np.cos(th)])
        X += rng.normal(0.0, self.noise * L, X.shape)
        with ctx.timed("embedding"):
            Q = ctx.plugin("embedder").fit_transform(X)
        if Q.shape[1] != 1:
            raise ConfigError(f"the pendulum's manifold is a curve: set embedder.n_components=1 "
                              f"(got {Q.shape[1]}).")
        with ctx.timed("manifold"):
            sm = SlowManifold(ctx.plugin("approximant"), self.n_bins).fit(X, Q)
            RL = ReducedLagrangian(sm, np.full(2, m),
                                   lambda x: (m * g * (x[1] + L), np.array([0.0, m * g])))
            x0 = np.array([L * np.sin(np.radians(self.amplitude)),
                           -L * np.cos(np.radians(self.amplitude))])
            q0, dist0 = sm.project(x0)
            qb, _ = sm.project(np.array([0.0, -L]))
            span = np.ptp(Q[:, 0])
            table = Table1D(RL.terms, Q.min() + 0.01 * span, Q.max() - 0.01 * span)
        T = exact_period(L, g, self.amplitude)
        dt = T / self.steps_per_period
        n = self.steps_per_period * self.n_periods
        with ctx.timed("integration"):
            t, q, E, _ = integrate_table(table, q0[0], 0.0, dt, n, self.save_every)
        # period from the first 100 periods at full time resolution: the long run's own
        # samples when it kept every step, else a short run from the same start
        k = self.steps_per_period * min(100, self.n_periods)
        if self.save_every == 1:
            t1, q1 = t[:k + 1], q[:k + 1]
        else:
            with ctx.timed("period"):
                t1, q1, _, _ = integrate_table(table, q0[0], 0.0, dt, k)
        period = crossing_period(t1, q1 - qb[0])
        E0 = E[0]
        tenth = max(len(E) // 10, 1)
        first = float(np.abs(E[:tenth] - E0).max() / E0)
        last = float(np.abs(E[-tenth:] - E0).max() / E0)
        per = max(self.steps_per_period // self.save_every, 1)
        n_full = len(E) // per
        band = ((E[:n_full * per] - E0) / E0).reshape(n_full, per)
        three = t1 <= 3 * T
        ds = xr.Dataset(coords={
            "cycle": ("cycle", np.arange(n_full), {"long_name": "period index", "units": "1"}),
            "time": ("time", t1[three], {"long_name": "time", "units": "s"})})
        _v(ds, "energy_error_max", band.max(axis=1), "max (E − E₀)/E₀ within each period",
           "1", ("cycle",))
        _v(ds, "energy_error_min", band.min(axis=1), "min (E − E₀)/E₀ within each period",
           "1", ("cycle",))
        _v(ds, "q", q1[three], "reduced coordinate q (Isomap), first three periods", "1",
           ("time",))
        for name, val, long, units in (
                ("period", period, "period of the reduced pendulum (upward crossings of the "
                 "bottom, first 100 periods)", "s"),
                ("period_reference", T, "exact period 4√(L/g) K(sin²(θ₀/2))", "s"),
                ("relative_error", abs(period / T - 1.0), "|period / reference − 1|", "1"),
                ("energy_error_first", first, "max |E − E₀|/E₀ over the first tenth", "1"),
                ("energy_error_last", last, "max |E − E₀|/E₀ over the last tenth", "1"),
                ("energy_drift", last - first, "energy_error_last − energy_error_first", "1"),
                ("n_periods", self.n_periods, "periods integrated", "1"),
                ("time_step", dt, "time step Δt", "s"),
                ("n_nodes", len(sm.nodes_), "LME nodes of the slow manifold", "1"),
                ("fit_residual", sm.residual_, "rms distance of the snapshots to X(q_i)", "m"),
                ("table_error", table.table_error, "max relative deviation of the tabulated "
                 "M̃ from the LME one", "1"),
                ("start_distance", dist0, "distance of the start to the manifold", "m")):
            _v(ds, name, val, long, units)
        ctx.log.info("period %.8g against %.8g (relative error %.2e); energy error %.3e in the "
                     "first tenth, %.3e in the last (%d periods)", period, T,
                     abs(period / T - 1), first, last, self.n_periods)
        ds.attrs["title"] = "reduced pendulum"
        return ds

    @staticmethod
    def report_figures(ds):
        from matplotlib.figure import Figure

        fig = Figure(figsize=(6.4, 3.6), layout="constrained")
        ax1, ax2 = fig.subplots(1, 2)
        c = ds["cycle"].values
        ax1.fill_between(c, ds["energy_error_min"].values, ds["energy_error_max"].values,
                         lw=0, alpha=0.6)
        ax1.set_xlabel("period")
        ax1.set_ylabel("(E − E₀)/E₀, range within each period")
        T = float(ds["period_reference"])
        ax2.plot(ds["time"].values / T, ds["q"].values)
        ax2.set_xlabel("time / exact period")
        ax2.set_ylabel("reduced coordinate q")
        return [(f"Energy over {int(ds['n_periods'])} periods and the first three periods "
                 f"(period error {float(ds['relative_error']):.1e})", fig)]

