"""The thesis' model-reduction comparison on the neo-Hookean body (issue 21's
``rom_neo_hookean``; thesis §5.4, Figs. 20–24; Millán & Arroyo, CMAME 261–262 (2013) 118, §5).

Snapshots of ``n_trajectories`` full trajectories (simulated here from seeded initial
conditions as ``full_trajectory`` draws them, or read from a ``rom_snapshots`` sweep given as
``snapshots``); the last ``n_test`` are held out. Of the others the first ``drop_fraction`` of
each is dropped (thesis: 500 of 4 000), the rest pruned to the boundary landmark nodes
(clamped ones excluded) and decimated to a cut-off ``decimation`` × the rms radius. The
intrinsic dimension is estimated a priori (correlation dimension, local PCA residual
variance) and a posteriori (reconstruction error e, Eq. 12, on held-out snapshots). Slow
manifolds: PCA of the full snapshots for each d in ``pca_dims`` (affine X(q)); each embedder
of ``nonlinear`` (NLIE, Isomap) for each d in ``nonlinear_dims`` on the landmarks, with the
LME parametrisation X(q) of the full configurations on the binned embedding (``approximant``
plugin). Each is integrated by the same α = 0 variational integrator from each held-out
trajectory's first retained state for ``test_duration``; D (Eq. 13) against the full
trajectory at its saved times. A reduced run that leaves the sampled region or whose Newton
step fails keeps the states reached; its D is not reported (NaN) and the run is flagged.
A test start farther than ``max_start_distance`` × rms radius from every training snapshot is
refused: the slow manifold knows nothing there.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from pointatlas.constraints import Interval
from pointatlas.stores_config import stores_config


@dataclass
class RomNeoHookeanSettings:
    n_trajectories: int = 12
    n_test: int = 2
    snapshots: str | None = None
    load_scale: float = 3.0
    load_angle: float = 30.0
    velocity_scale: float = 0.5
    drop_fraction: float = 0.125
    decimation: float = 0.01
    pca_dims: list = field(default_factory=lambda: list(range(1, 21)))
    nonlinear: list = field(default_factory=lambda: ["nlie", "isomap"])
    nonlinear_dims: list = field(default_factory=lambda: [1, 2])
    nlie_neighbors: int = 200
    nlie_alpha: float = 0.99
    isomap_neighbors: int = 12
    n_bins: int = 60
    n_bins_1d: int = 400
    dt: float = 1.0e-4
    test_duration: float = 1.0
    max_start_distance: float = 0.1
    n_error_samples: int = 60
    n_map: int = 40
    n_frames: int = 6
    strip_pca_dim: int = 10
    parameter_constraints: ClassVar[dict] = {
        "n_trajectories": [Interval(int, 2, None)], "n_test": [Interval(int, 1, None)],
        "load_scale": [Interval(float, 0, None)], "load_angle": [Interval(float, 0, 90)],
        "velocity_scale": [Interval(float, 0, None)],
        "drop_fraction": [Interval(float, 0, 1, closed="left")],
        "decimation": [Interval(float, 0, 1)],
        "nlie_neighbors": [Interval(int, 2, None)],
        "nlie_alpha": [Interval(float, 0, 1, closed="right")],
        "isomap_neighbors": [Interval(int, 2, None)], "n_bins": [Interval(int, 2, None)],
        "n_bins_1d": [Interval(int, 2, None)],
        "dt": [Interval(float, 0, None, closed="neither")],
        "test_duration": [Interval(float, 0, None, closed="neither")],
        "max_start_distance": [Interval(float, 0, None, closed="neither")],
        "n_error_samples": [Interval(int, 1, None)], "n_map": [Interval(int, 2, None)],
        "n_frames": [Interval(int, 2, None)], "strip_pca_dim": [Interval(int, 1, None)]}


@stores_config
class RomNeoHookean:
    """PCA against nonlinear (NLIE, Isomap + LME) reductions of the neo-Hookean body."""

    Config = RomNeoHookeanSettings
    description: ClassVar[str] = ("The thesis' model-reduction comparison: trajectory "
                                  "distance and reconstruction error of PCA and nonlinear "
                                  "slow manifolds against the full neo-Hookean model.")

    @staticmethod
    def report_figures(ds):
        from pointatlas_studies.rom_figures import figures

        return figures(ds)

    def check(self):
        from pointatlas.errors import ConfigError

        if self.snapshots is None and self.n_test >= self.n_trajectories:
            raise ConfigError(f"study.n_test={self.n_test} leaves no training trajectory of "
                              f"{self.n_trajectories}; lower n_test or raise n_trajectories.")
        dims = [int(d) for d in list(self.pca_dims) + list(self.nonlinear_dims)]
        if not dims or min(dims) < 1:
            raise ConfigError("study.pca_dims and study.nonlinear_dims must be positive "
                              "integers, e.g. pca_dims=[1,2,3] nonlinear_dims=[1,2].")
        bad = sorted(set(self.nonlinear) - {"nlie", "isomap", "pca", "mlle", "lle"})
        if bad:
            raise ConfigError(f"study.nonlinear names unknown embedders {bad}; use nlie, "
                              f"isomap (or lle, mlle).")

    def run(self, ctx):
        from pointatlas.errors import ConfigError
        from pointatlas_studies.full_trajectory import FullTrajectory
        from pointatlas_studies.rom_comparison import compare
        from pointatlas_studies.rom_training import check_mesh, read_sweep, simulate

        self.check()
        physics = ctx.plugin("physics")
        if not hasattr(physics, "build_body"):
            raise ConfigError("study=rom_neo_hookean needs an elastic body "
                              "(physics=neo_hookean_2d).")
        body = physics.build_body()
        if self.snapshots:
            snap = read_sweep(self.snapshots, self.drop_fraction)
            if self.n_test >= snap.n_trajectories:
                raise ConfigError(f"the sweep {self.snapshots} holds {snap.n_trajectories} "
                                  f"trajectories: study.n_test={self.n_test} leaves none to "
                                  f"train on; lower n_test.")
            full_wall = np.nan
        else:
            traj = FullTrajectory(load_scale=self.load_scale, load_angle=self.load_angle,
                                  velocity_scale=self.velocity_scale)
            snap = simulate(ctx, traj, self.n_trajectories, self.drop_fraction)
            full_wall = ctx.timings["full_trajectories"] / (
                self.n_trajectories * float(snap.time[-1] - snap.time[0]))
        check_mesh(snap, body)
        ds = compare(ctx, self, body, snap)
        if np.isnan(full_wall):
            full_wall = _time_full(ctx, physics, snap)
        ds["full_wall_per_time"] = ((), full_wall, {
            "long_name": "wall time of the full model per simulated time unit",
            "units": "s"})
        ds["speedup"] = ds["full_wall_per_time"] / ds["reduced_wall_per_time"]
        ds["speedup"].attrs = {"long_name": "full over reduced wall time per simulated time",
                               "units": "1"}
        ds.attrs["title"] = "model reduction: PCA against nonlinear slow manifolds"
        ds.attrs["snapshot_sources"] = "; ".join(snap.sources)
        if ds.attrs.get("warnings"):
            ctx.log.warning("%s", ds.attrs["warnings"])
        return ds


def _time_full(ctx, physics, snap, n_steps: int = 2000) -> float:
    """Wall time per simulated time unit of the full model from the first snapshot (a run of
    ``n_steps`` after a warm-up of a few)."""
    import time

    x0 = snap.position[0, snap.start].reshape(-1, 2)
    v0 = snap.velocity[0].reshape(-1, 2)
    physics.solve(ctx, x0=x0, v0=v0, n_steps=10)
    t0 = time.perf_counter()
    physics.solve(ctx, x0=x0, v0=v0, n_steps=n_steps)
    return (time.perf_counter() - t0) / (n_steps * float(physics.dt))
