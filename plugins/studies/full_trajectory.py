"""One trajectory of the full elastic model, its snapshots along ``time`` (issue 21's
``rom_snapshots``; thesis §5.4: 35 trajectories from different initial conditions).

The initial condition comes from the config and the run's seed: the body starts in static
equilibrium under a body acceleration of magnitude ``load_scale`` in a random direction
within ``load_angle`` degrees of the horizontal (left or right), and with the velocity field
v = L (X − X_c) of a random 2 × 2 gradient L of Frobenius norm ``velocity_scale`` (zero on the
clamp); then it moves under the physics' gravity. The physics (``neo_hookean_2d``) is used
through its Config and ``solve`` only. Gather a sweep's snapshots with
``pointatlas.open_sweep`` (dims ``run``/swept keys × ``time`` × ``node`` × ``dim``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from pointatlas.constraints import Interval
from pointatlas.stores_config import stores_config


@dataclass
class FullTrajectorySettings:
    load_scale: float = 2.0
    load_angle: float = 30.0
    velocity_scale: float = 0.5
    parameter_constraints: ClassVar[dict] = {
        "load_scale": [Interval(float, 0, None)], "load_angle": [Interval(float, 0, 90)],
        "velocity_scale": [Interval(float, 0, None)]}


@stores_config
class FullTrajectory:
    """A trajectory of the full model from a seeded initial condition (snapshots)."""

    Config = FullTrajectorySettings
    description: ClassVar[str] = ("One full-model trajectory from a seeded random initial "
                                  "condition, its snapshots along time (model reduction).")

    def initial_condition(self, rng) -> dict:
        side = rng.choice([-1.0, 1.0])
        ang = np.radians(rng.uniform(-self.load_angle, self.load_angle))
        load = self.load_scale * np.array([side * np.cos(ang), np.sin(ang)])
        L = rng.normal(size=4)
        L *= self.velocity_scale / np.linalg.norm(L)
        return {"initial_load": [float(v) for v in load],
                "initial_velocity_gradient": [float(v) for v in L]}

    def run(self, ctx):
        from pointatlas.errors import ConfigError

        ic = self.initial_condition(ctx.rng("initial_condition"))
        physics = ctx.plugin("physics", **ic)
        if not hasattr(physics, "build_body"):
            raise ConfigError("study=full_trajectory needs an elastic body "
                              "(physics=neo_hookean_2d).")
        with ctx.timed("trajectory"):
            ds = physics.solve(ctx)
        ds["initial_load"] = (("dim",), np.asarray(ic["initial_load"]), {
            "long_name": "body acceleration of the initial static pre-load",
            "units": "length / time^2"})
        ds["initial_velocity_gradient"] = (("gradient",), np.asarray(
            ic["initial_velocity_gradient"]), {"long_name": "L of v₀ = L (X − X_c), row-major",
                                               "units": "1 / time"})
        ds.attrs["title"] = "full-model trajectory (snapshots)"
        ctx.log.info("trajectory: %d snapshots of %d nodes, energy error %.2e",
                     ds.sizes["time"], ds.sizes["node"], float(ds["energy_error"]))
        return ds
