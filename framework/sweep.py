"""Open a whole multirun as one Dataset, with the swept parameters as dimensions."""
from __future__ import annotations

import itertools
import json
import logging
import os
from pathlib import Path

import numpy as np
import xarray as xr

from .errors import InputError
from .results import RESULTS_NAME, open_run, write_netcdf_atomic


def parse_override(text: str) -> tuple[str, str]:
    key, _, value = text.partition("=")
    return key.lstrip("+~"), value


def typed(value: str):
    """'12' -> 12, '0.5' -> 0.5, other strings unchanged (for coordinates)."""
    for kind in (int, float):
        try:
            return kind(value)
        except ValueError:
            pass
    return value


def run_dirs(sweep_dir: Path) -> list[Path]:
    """Job directories of a multirun (those holding a results file), in job order."""
    found = [p.parent for p in sweep_dir.glob(f"*/{RESULTS_NAME}")]

    def order(p: Path):
        return (0, int(p.name)) if p.name.isdigit() else (1, p.name)

    return sorted(found, key=order)


def swept_parameters(overrides: list[list[str]]) -> list[str]:
    """Override keys whose value differs between runs."""
    values: dict[str, set] = {}
    for ov in overrides:
        for key, value in map(parse_override, ov):
            values.setdefault(key, set()).add(value)
    keys = [k for k, v in values.items() if len(v) > 1]
    # keys absent from some runs also vary
    keys += [k for k in values if k not in keys and any(k not in dict(map(parse_override, o)) for o in overrides)]
    return sorted(keys)


SWEEP_FILE = "sweep.nc"
log = logging.getLogger(__name__)


def _fresh_sweep_file(sweep_dir: Path, dirs: list[Path]) -> Path | None:
    """``sweep.nc`` if it is newer than every job's results (a job rerun since makes it stale)."""
    path = sweep_dir / SWEEP_FILE
    if not path.is_file():
        return None
    written = path.stat().st_mtime
    return path if all((d / RESULTS_NAME).stat().st_mtime <= written for d in dirs) else None


def write_sweep(path: str | os.PathLike, sweep_id: str | None = None) -> Path | None:
    """Write the combined Dataset of a finished multirun to ``<sweep dir>/sweep.nc`` (to a
    temporary name, then renamed; large variables chunked as a run's results), so it is not
    assembled again on each read. None when the directory holds no finished job."""
    sweep_dir = Path(path)
    if not run_dirs(sweep_dir):
        return None
    ds = _assemble(sweep_dir)
    if sweep_id:
        ds.attrs["sweep_id"] = sweep_id
    return write_netcdf_atomic(ds, sweep_dir / SWEEP_FILE)


def open_sweep(path: str | os.PathLike, lazy: bool = False) -> xr.Dataset:
    """One Dataset for a multirun directory: its ``sweep.nc`` when the sweep finished (and no
    job was rerun since, and it reads), else assembled from the jobs' results.

    By default everything is read into memory and the files are closed. With ``lazy=True``
    (needs dask) nothing is read yet: variables are dask arrays in the files' own chunks
    (see :func:`~pointatlas.results.open_run`), the files stay open until ``ds.close()`` (or
    the end of a ``with open_sweep(..., lazy=True) as ds:`` block), and values are read as
    they are computed, so a sweep larger than memory can be reduced run by run.

    When the runs form a full grid over the swept override keys, those keys are dimensions
    named without dots (``source.n_points`` -> ``source_n_points``, the key in the
    coordinate's ``override`` attr); otherwise runs are stacked along a ``run`` dim with the
    swept values as coordinates. Variables that are integers in every run stay integers.
    Attrs come from the first run, plus ``sweep_params`` (the dims), ``sweep_overrides`` (the
    keys) and ``run_attrs`` (every run's attrs, JSON, in job order).
    """
    sweep_dir = Path(path)
    dirs = run_dirs(sweep_dir) if sweep_dir.is_dir() else []
    if not dirs:
        raise InputError(
            f"no runs with {RESULTS_NAME} under {sweep_dir}. Pass the directory of a "
            "`pointatlas --multirun` sweep (it holds one numbered folder per job)."
        )
    fresh = _fresh_sweep_file(sweep_dir, dirs)
    if fresh is not None:
        try:
            ds = open_run(fresh, lazy=lazy)
        except InputError as exc:   # damaged: the jobs' results are the source of truth
            log.warning("%s could not be read (%s); reading the %d jobs instead", fresh,
                        type(exc).__name__, len(dirs))
        else:
            ds.attrs["sweep_dir"] = str(sweep_dir)
            return ds
    return _assemble(sweep_dir, lazy)


def dim_name(key: str, taken=()) -> str:
    """The dimension name of a swept override key: ``source.n_points`` -> ``source_n_points``
    (CF names have no dots); ``_swept`` appended if a results variable has that name."""
    name = key.replace(".", "_").replace("/", "_")
    return name + "_swept" if name in taken else name


def _assemble(sweep_dir: Path, lazy: bool = False) -> xr.Dataset:
    dirs = run_dirs(sweep_dir)
    runs = []
    try:
        for d in dirs:
            runs.append(open_run(d, lazy=lazy))
    except Exception:
        for ds in runs:
            ds.close()
        raise
    overrides = [json.loads(ds.attrs.get("overrides", "[]")) for ds in runs]
    keys = swept_parameters(overrides)
    values = [[typed(dict(map(parse_override, ov)).get(k, "")) for k in keys] for ov in overrides]
    stacked = xr.concat(
        [_indexed(ds.drop_attrs(deep=False)) for ds in runs],
        dim="run", coords="minimal", compat="override", join="outer",
    )
    names = [dim_name(k, stacked.variables) for k in keys]
    stacked = stacked.assign_coords(run=("run", np.arange(len(runs)), {"long_name": "run index", "units": "1"}))
    stacked = stacked.assign_coords(
        run_dir=("run", [d.name for d in dirs], {"long_name": "run directory", "units": "1"})
    )
    for i, (key, name) in enumerate(zip(keys, names)):
        stacked = stacked.assign_coords({name: ("run", [v[i] for v in values])})
    axes = [sorted({v[i] for v in values}, key=str) for i in range(len(keys))]
    grid = set(itertools.product(*axes))
    is_grid = keys and len(grid) == len(values) and grid == {tuple(v) for v in values}
    out = stacked
    if is_grid:
        out = stacked.drop_vars("run_dir")
        if len(keys) == 1:
            out = out.swap_dims(run=names[0]).drop_vars("run").sortby(names[0])
        else:
            out = out.set_index(run=names).unstack("run")
    for key, name in zip(keys, names):
        out[name].attrs.update({"long_name": f"swept parameter {key}", "units": "1",
                                "override": key})
    _restore_integers(out, runs)
    out.attrs = dict(runs[0].attrs)
    out.attrs["sweep_params"] = json.dumps(names)
    out.attrs["sweep_overrides"] = json.dumps(keys)
    out.attrs["run_attrs"] = json.dumps([{"run_dir": d.name, **{k: _plain(v) for k, v in
                                                                 ds.attrs.items()}}
                                         for d, ds in zip(dirs, runs)])
    out.attrs["sweep_dir"] = str(sweep_dir)
    if lazy:   # the runs' files stay open under the dask arrays until the sweep is closed
        out.set_close(lambda: [ds.close() for ds in runs])
    return out


def _indexed(ds: xr.Dataset) -> xr.Dataset:
    """Dims without a coordinate get 0..n-1, so that runs whose sizes differ there (a mesh
    of another size) are padded instead of refused."""
    bare = {d: np.arange(n) for d, n in ds.sizes.items() if d not in ds.coords}
    return ds.assign_coords(bare) if bare else ds


def _restore_integers(out: xr.Dataset, runs: list[xr.Dataset]) -> None:
    """Variables that are integers in every run stay integers when stacking needed no
    padding: the variable is in every run with the sizes it has in ``out`` along its own
    dims (an outer join that added a missing value would have enlarged one). Decided from
    the sizes alone, so a lazy sweep reads nothing."""
    for name in list(out.data_vars):
        have = [ds[name] for ds in runs if name in ds]
        kinds = {v.dtype for v in have}
        if len(have) != len(runs) or len(kinds) != 1 or not np.issubdtype(
                next(iter(kinds)), np.integer) or out[name].dtype == next(iter(kinds)):
            continue
        if all(out.sizes[d] == n for v in have for d, n in v.sizes.items()):
            out[name] = out[name].astype(next(iter(kinds)))


def _plain(value):
    return value.tolist() if hasattr(value, "tolist") else value
