"""Snapshots of the full model for a model reduction (issue 21, thesis §5.4 "Training set";
Millán & Arroyo, CMAME 261–262 (2013) 118, §5.1): simulated here, one trajectory per seed as
``study=full_trajectory`` would, or read from a ``rom_snapshots`` multirun directory, and
checked to share one mesh, one clamp and so one set of boundary landmarks.

Configurations are flattened node-major, x = (x₀, y₀, x₁, y₁, …) (length D = 2 n_nodes), in
the physics' length unit; ``time`` in its time unit.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pointatlas.errors import InputError


@dataclass
class Snapshots:
    """``position`` (n_trajectories, n_time, D); ``velocity`` (n_trajectories, D) only at the
    snapshot ``start`` (where reduced runs start: the first one kept after the dropped
    transient), ``time`` (n_time,), the mesh arrays and where the snapshots came from."""

    position: np.ndarray
    velocity: np.ndarray
    start: int
    time: np.ndarray
    triangles: np.ndarray
    reference: np.ndarray
    clamped: np.ndarray
    nodal_mass: np.ndarray
    sources: list

    @property
    def n_trajectories(self) -> int:
        return self.position.shape[0]


def start_index(n_time: int, drop_fraction: float) -> int:
    """The first snapshot kept after dropping ``drop_fraction`` of ``n_time``."""
    return int(drop_fraction * n_time)


def _arrays(ds, drop_fraction):
    pos = ds["position"].values
    k = start_index(pos.shape[0], drop_fraction)
    return (pos.reshape(pos.shape[0], -1), ds["velocity"].isel(time=k).values.ravel(),
            ds["time"].values)


def simulate(ctx, trajectory, n_trajectories: int, drop_fraction: float) -> Snapshots:
    """``n_trajectories`` runs of the physics from the seeded initial conditions of
    ``trajectory`` (a :class:`~.full_trajectory.FullTrajectory`), each from its own stream."""
    P, V, srcs, time = [], [], [], None
    for i in range(n_trajectories):
        ic = trajectory.initial_condition(ctx.rng(f"initial_condition_{i}"))
        with ctx.timed("full_trajectories"):
            ds = ctx.plugin("physics", **ic).solve(ctx)
        p, v, time = _arrays(ds, drop_fraction)
        P.append(p)
        V.append(v)
        srcs.append(f"simulated trajectory {i}")
        ctx.log.info("full trajectory %d/%d: %d snapshots", i + 1, n_trajectories, len(time))
    return Snapshots(np.stack(P), np.stack(V), start_index(len(time), drop_fraction), time,
                     ds["face_node_connectivity"].values,
                     np.column_stack([ds["node_x"].values, ds["node_y"].values]),
                     ds["clamped"].values.astype(bool), ds["nodal_mass"].values, srcs)


def read_sweep(path, drop_fraction: float) -> Snapshots:
    """The snapshots of every run of a ``rom_snapshots`` multirun directory; all runs must
    share the mesh, the clamp (hence the landmarks) and the saved times."""
    from pointatlas.results import open_run
    from pointatlas.sweep import run_dirs

    sweep = Path(path)
    dirs = run_dirs(sweep) if sweep.is_dir() else []
    if not dirs:
        raise InputError(f"study.snapshots={path}: no runs found there. Give the directory "
                         f"of a `pointatlas experiment=rom_snapshots --multirun` sweep.")
    first = None
    P, V = [], []
    for d in dirs:
        ds = open_run(d)
        if "position" not in ds:
            raise InputError(f"run {d} holds no `position` snapshots; study.snapshots must be "
                             f"a sweep of experiment=rom_snapshots.")
        tri = ds["face_node_connectivity"].values
        ref = np.column_stack([ds["node_x"].values, ds["node_y"].values])
        clamp = ds["clamped"].values.astype(bool)
        p, v, t = _arrays(ds, drop_fraction)
        if first is None:
            first = (d, tri, ref, clamp, t, ds["nodal_mass"].values)
        else:
            d0, tri0, ref0, clamp0, t0, _ = first
            if tri.shape != tri0.shape or ref.shape != ref0.shape or not (
                    np.array_equal(tri, tri0) and np.allclose(ref, ref0, atol=1e-12)):
                raise InputError(
                    f"snapshot sweep {path}: run {d.name} has a different mesh "
                    f"({len(tri)} triangles, {len(ref)} nodes) from run {d0.name} "
                    f"({len(tri0)} triangles, {len(ref0)} nodes); a reduced model needs one "
                    f"mesh. Rerun the sweep with the same physics mesh settings.")
            if not np.array_equal(clamp, clamp0):
                raise InputError(
                    f"snapshot sweep {path}: run {d.name} clamps other nodes than run "
                    f"{d0.name}, so their landmark sets differ; rerun the sweep with one "
                    f"physics.clamp.")
            if t.shape != t0.shape or not np.allclose(t, t0):
                raise InputError(
                    f"snapshot sweep {path}: run {d.name} saved {len(t)} snapshots at other "
                    f"times than run {d0.name} ({len(t0)}); rerun with one physics.n_steps, "
                    f"dt and save_every.")
        P.append(p)
        V.append(v)
    _, tri, ref, clamp, t, mass = first
    return Snapshots(np.stack(P), np.stack(V), start_index(len(t), drop_fraction), t, tri,
                     ref, clamp, mass, [str(d) for d in dirs])


def check_mesh(snap: Snapshots, body) -> None:
    """The physics the study integrates with must be the one that made the snapshots."""
    ref = np.asarray(body.reference)
    if ref.shape != snap.reference.shape or not np.allclose(ref, snap.reference, atol=1e-12) \
            or not np.array_equal(np.asarray(body.clamped, bool), snap.clamped):
        raise InputError(
            f"the snapshots' mesh ({len(snap.reference)} nodes) is not the physics' mesh "
            f"({len(ref)} nodes) or clamps other nodes; set the physics options of this run "
            f"as in the snapshot sweep (physics.n_triangles, mesh_file, clamp).")


def rms_radius(X: np.ndarray) -> float:
    """√(mean |x − x̄|²) of the rows of X, the training set's size."""
    return float(np.sqrt(np.mean(np.sum((X - X.mean(axis=0)) ** 2, axis=1))))
