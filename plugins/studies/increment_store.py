"""``increments.nc``: the converged increments of a load path, durable after every increment.

After every converged increment the shell path study rewrites ``increments.nc`` in its run
directory with all increments so far (:func:`write_increments`): the path Dataset plus the
nodal displacements, and the path follower's state after each increment
(:class:`pointatlas_solvers.path_state.PathState`, variables ``path_state_*``),
so that ``study.resume_from`` continues the path exactly (:func:`read_increments`). The file
is written under a temporary name in the same directory (``.increments.nc.<random>.tmp``),
flushed to disk, renamed over ``increments.nc`` and the directory is flushed too: a kill at
any moment leaves the previous complete file or the new one, never a partial one, and
:func:`pointatlas.run_files.remove_partial_files` deletes what an interrupted write left.

The settings the path depends on (the plugins chosen, their configs, the seed) are stored in
the attribute ``resume_settings`` (JSON); a resume whose settings differ is refused, naming
the first differing key (:func:`check_settings`).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from pointatlas.errors import ConfigError, InputError
from pointatlas.results import write_netcdf_atomic
from pointatlas.run_files import remove_partial_files

NAME = "increments.nc"
#: what interrupted writes of increments.nc leave (this module's and older versions')
FORMAT = 2   # 2: with the path state (format 1 files had only the displacements)
ONE = {"units": "1"}


def run_settings(ctx, exclude=("study.resume_from",)) -> dict:
    """{key: JSON value} of what a path depends on: the plugin chosen for every family, its
    resolved config (``family.key``) and the seed."""
    from pointatlas.context import plugin_kwargs

    out = {"seed": json.dumps(int(ctx.seed))}
    for family, name in sorted(ctx.choices.items()):
        out[family] = json.dumps(name)
        for key, value in sorted(plugin_kwargs(ctx.config.get(family)).items()):
            if f"{family}.{key}" not in exclude:
                out[f"{family}.{key}"] = json.dumps(value, sort_keys=True, default=str)
    return out


def check_settings(path: Path, saved: dict, current: dict) -> None:
    """Refuse to resume when the saved run's settings differ from this run's (ConfigError
    naming the first differing key)."""
    for key in sorted(set(saved) | set(current)):
        if saved.get(key) != current.get(key):
            raise ConfigError(
                f"study.resume_from: {path} was computed with {key} = "
                f"{saved.get(key, '(not set)')}, this run has {key} = "
                f"{current.get(key, '(not set)')}; a resumed path must use the same settings: "
                f"rerun with {key} as saved, or without study.resume_from.")


def write_increments(path: Path, ds, records, settings: dict) -> None:
    """Write the path Dataset ``ds`` of ``records`` (the increments, each with its
    ``state``) and the path state to ``path``, durably (temporary file, fsync, rename,
    fsync of the directory)."""
    ds = ds.copy()
    ds["nodal_displacement"] = (("increment", "node", "dim"), np.stack([r.U for r in records]),
                                {"long_name": "nodal displacements U (ghosts included)",
                                 "units": "length"})
    ds = _with_states(ds, [r.state for r in records])
    ds.attrs.update(resume_settings=json.dumps(settings, sort_keys=True),
                    increments_format=FORMAT)
    write_netcdf_atomic(ds, path)


def _with_states(ds, states):
    """Adds the ``path_state_*`` variables (one row per increment)."""
    nodes = ds["nodal_displacement"].shape[1]
    nan = np.full((nodes, 3), np.nan)
    ds["path_state_displacement"] = (("increment", "node", "dim"), np.stack(
        [s.U.reshape(-1, 3) for s in states]), {
        "long_name": "nodal displacements the path goes on from", "units": "length"})
    ds["path_state_previous"] = (("increment", "node", "dim"), np.stack(
        [nan if s.previous is None else s.previous.reshape(-1, 3) for s in states]), {
        "long_name": "load control: U of the previous increment (secant predictor); arc "
                     "length: ΔU of the last increment on the control points (NaN: none)",
        "units": "length"})
    ds["path_state_multiplier"] = (("increment", "constraint"), np.stack(
        [s.mu for s in states]), {"long_name": "multipliers μ of the supports C U = λ g",
                                  "units": "force"})
    for name in states[0].SCALARS:
        ds[f"path_state_{name}"] = (("increment",), np.array([getattr(s, name) for s in states],
                                                             dtype=float), {
            **ONE, "long_name": f"path follower state: {name}"})
    levels = sorted({x for s in states for x in s.pending})
    if levels:
        ds = ds.assign_coords(path_level=("path_level", levels, {
            **ONE, "long_name": "tabulated load factor the path lands on"}))
        ds["path_state_pending"] = (("increment", "path_level"), np.array(
            [[x in set(s.pending) for x in levels] for s in states], np.int8), {
            **ONE, "long_name": "1 if the level is still to be reached"})
    ds.attrs["path_control"] = states[0].control
    return ds


def check_resume_dir(run_dir) -> Path:
    """``run_dir``/increments.nc, or InputError naming the path and the fix (a check that
    needs no model: it runs at start-up)."""
    folder = Path(run_dir)
    fix = "give the run directory of an interrupted run, or drop study.resume_from"
    if not folder.is_dir():
        raise InputError(f"study.resume_from={run_dir}: no such directory; {fix}.")
    path = folder / NAME
    if not path.is_file():
        raise InputError(f"study.resume_from={run_dir}: the directory has no {NAME} (the run "
                         f"saved no converged increment); {fix}.")
    return path


def load_increments_file(run_dir):
    """(path, Dataset) of ``run_dir``/increments.nc, after removing what interrupted writes
    left; InputError naming the fix if it is missing or cannot be read."""
    import xarray as xr

    path = check_resume_dir(run_dir)
    remove_partial_files(path.parent)
    try:
        return path, xr.load_dataset(path, engine="netcdf4")
    except Exception as exc:   # netCDF raises OSError, ValueError, RuntimeError, KeyError
        raise InputError(f"study.resume_from={run_dir}: {path} cannot be read ({exc}); it is "
                         f"damaged: rerun without study.resume_from.") from exc


def read_increments(run_dir, settings: dict):
    """The increments stored in ``run_dir``/increments.nc (oldest first, each with its
    ``state``), after checking the file is complete and was computed with ``settings``.
    InputError if the directory or file is missing or unreadable; ConfigError if the
    settings differ."""
    path, old = load_increments_file(run_dir)
    if int(old.attrs.get("increments_format", 1)) < FORMAT or "resume_settings" not in old.attrs:
        raise InputError(f"study.resume_from={run_dir}: {path} was written by an older "
                         "pointatlas without the path state a resume needs; rerun without "
                         "study.resume_from.")
    check_settings(path, json.loads(old.attrs["resume_settings"]), settings)
    try:
        return _records(old)
    except (KeyError, ValueError, IndexError) as exc:
        raise InputError(f"study.resume_from={run_dir}: {path} lacks {exc} or holds it in "
                         "another shape; it is damaged: rerun without study.resume_from.") from exc


def _records(old) -> list:
    """The Increments (with their PathState) of an increments Dataset."""
    from pointatlas_solvers.increment import Increment
    from pointatlas_solvers.path_state import PathState

    def row(name, k, default=np.nan):
        return old[name].values[k] if name in old else default

    levels = old["path_level"].values if "path_level" in old.coords else np.zeros(0)
    records = []
    for k in range(old.sizes["increment"]):
        previous = old["path_state_previous"].values[k]
        values = {name: float(old[f"path_state_{name}"].values[k]) for name in
                  PathState.SCALARS}
        state = PathState(
            str(old.attrs["path_control"]), values.pop("load_factor"),
            old["path_state_displacement"].values[k].ravel().copy(),
            old["path_state_multiplier"].values[k].copy(), values.pop("step"),
            previous=None if np.isnan(previous).all() else previous.ravel().copy(),
            pending=tuple(float(x) for x, on in zip(levels, row("path_state_pending", k,
                                                                np.zeros(len(levels)))) if on),
            switches=int(values.pop("switches")),
            check_switch=bool(values.pop("check_switch")),
            adapt_iterations=int(values.pop("adapt_iterations")), **values)
        records.append(Increment(
            float(old["load_factor"].values[k]), old["nodal_displacement"].values[k].copy(),
            int(old["newton_iterations"].values[k]), [],
            {part: float(old[f"energy_{part}"].values[k])
             for part in ("total", "membrane", "bending")},
            int(old["negative_pivots"].values[k]), bool(old["stable"].values[k]),
            float(old["increment_time"].values[k]),
            reactions=old["reaction"].values[k].copy() if "reaction" in old else None,
            snapped=bool(old["snapped"].values[k]), state=state))
    return records
