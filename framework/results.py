"""Results I/O: every run writes one CF-style netCDF file, atomically.

A results file is an xarray Dataset with named dims and coords, ``long_name``/``units`` on
every variable, scalar metrics as 0-d variables and the provenance as global attrs
(see :data:`REQUIRED_ATTRS`). Writing goes to a temporary file in the same directory that
is renamed over ``results.nc`` only when complete, so a killed run never leaves a
truncated file; the temporary files a killed write leaves behind (``.results.nc.*.tmp``) are
removed by the next run in that directory (:func:`remove_partial_files`) and by
``pointatlas-runs gc``. Results files get the permissions of the user's umask, like every
other file a run writes.
"""
from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .errors import InputError, SchemaError
from .run_files import RESULTS_NAME

SCHEMA_VERSION = 1
REQUIRED_ATTRS = (
    "Conventions", "title", "source", "history", "config", "overrides", "git_commit",
    "seed", "hostname", "wall_time_s", "status",
)


def attr_value(value: Any):
    """Convert a Python value to something netCDF accepts as an attribute."""
    if value is None:
        return ""
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, (int, np.integer)) and not -2**63 <= int(value) < 2**63:
        return np.uint64(value)  # seeds up to 2**64 - 1 (netCDF 'u8')
    if isinstance(value, (str, int, float, np.integer, np.floating)):
        return value
    if isinstance(value, np.ndarray) and value.dtype.kind in "iuf":
        return value
    if isinstance(value, (dict, list, tuple)):
        return json.dumps(value, sort_keys=True, default=str)
    return str(value)


def clean_attrs(attrs: dict) -> dict:
    return {str(k): attr_value(v) for k, v in attrs.items()}


def metric_names(ds: xr.Dataset) -> list[str]:
    """Names of the scalar (0-d, numeric) data variables of a results Dataset."""
    return sorted(
        name for name, var in ds.data_vars.items() if var.ndim == 0 and var.dtype.kind in "biuf"
    )


def metric_values(ds: xr.Dataset) -> dict[str, float]:
    """The scalar metrics of a results Dataset as floats."""
    return {name: float(ds[name].values) for name in metric_names(ds)}


def check_variables(ds: xr.Dataset) -> None:
    """Every variable must say what it is and in which units (CF ``long_name``, ``units``)."""
    missing = [
        name for name, var in {**ds.data_vars, **ds.coords}.items()
        if not {"long_name", "units"} <= set(var.attrs)
    ]
    if missing:
        raise ValueError(
            f"results variables without 'long_name'/'units' attrs: {sorted(map(str, missing))}. "
            "Every variable and coordinate must carry both (units '1' if dimensionless)."
        )


def write_results(ds: xr.Dataset, path: str | os.PathLike, attrs: dict | None = None) -> Path:
    """Write ``ds`` (with extra global ``attrs``) to ``path`` atomically; return the path.

    Variable and global attrs are converted to netCDF-compatible types (dicts and lists
    become JSON strings). The file appears under its final name only once complete.
    """
    path = Path(path)
    if path.is_dir():
        path = path / RESULTS_NAME
    path.parent.mkdir(parents=True, exist_ok=True)
    out = ds.copy()
    out.attrs = clean_attrs({**ds.attrs, **(attrs or {}), "pointatlas_schema": SCHEMA_VERSION})
    for name in list(out.variables):
        out[name].attrs = clean_attrs(out[name].attrs)
    return write_netcdf_atomic(out, path)


def write_netcdf_atomic(ds: xr.Dataset, path: str | os.PathLike) -> Path:
    """Write ``ds`` to ``path`` durably: a temporary file beside it (umask mode), fsync,
    rename over ``path``, fsync of the directory; a kill at any moment leaves the old file or
    the new one, and at worst a ``.<name>.*.tmp`` leftover (:func:`remove_partial_files`)."""
    path = Path(path)
    tmp = _temporary_name(path)
    try:
        ds.to_netcdf(tmp, engine="netcdf4")
        _publish(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _temporary_name(path: Path) -> str:
    """A fresh name ``.<name>.<random>.tmp`` beside ``path`` (created empty, umask mode)."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    os.chmod(tmp, 0o666 & ~_umask())
    return tmp


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _publish(tmp: str, path: Path) -> None:
    """fsync ``tmp``, rename it over ``path`` and fsync the directory (the rename is durable)."""
    with open(tmp, "rb") as fh:
        os.fsync(fh.fileno())
    os.replace(tmp, path)
    try:
        dir_fd = os.open(path.parent, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(dir_fd)
    except OSError:
        pass
    finally:
        os.close(dir_fd)


def write_text_atomic(path: str | os.PathLike, text: str) -> Path:
    """Write a small text file under its final name only once complete."""
    path = Path(path)
    tmp = _temporary_name(path)
    try:
        with open(tmp, "w") as fh:
            fh.write(text)
        _publish(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def results_path(path: str | os.PathLike) -> Path:
    """``path`` itself if it is a file, else ``path/results.nc``; clear error if absent."""
    path = Path(path)
    target = path / RESULTS_NAME if path.is_dir() else path
    if not target.is_file():
        raise InputError(
            f"no results file at {target}. Pass a run directory that contains {RESULTS_NAME} "
            "(list runs with `pointatlas-runs list`)."
        )
    return target


def open_run(path: str | os.PathLike) -> xr.Dataset:
    """Open one run's results (a run directory or its ``results.nc``) fully into memory.

    Raises :class:`~pointatlas.errors.SchemaError` for a file written by a newer schema.
    """
    target = results_path(path)
    try:
        with xr.open_dataset(target, engine="netcdf4") as ds:
            ds = ds.load()
    except (OSError, ValueError, RuntimeError, KeyError) as exc:
        size = target.stat().st_size if target.exists() else 0
        what = "is empty (0 bytes)" if size == 0 else f"is not a readable netCDF file ({exc})"
        raise InputError(
            f"{target} {what}: the run that wrote it did not finish, or the file was damaged "
            "afterwards. Rerun that run (its config is in .hydra/config.yaml beside it) or "
            "remove the directory."
        ) from None
    version = int(ds.attrs.get("pointatlas_schema", 0))
    if version > SCHEMA_VERSION:
        raise SchemaError(
            f"{target} was written with results schema {version}, newer than this pointatlas "
            f"understands ({SCHEMA_VERSION}). Upgrade pointatlas (pip install -U pointatlas)."
        )
    if version < 1:
        raise SchemaError(
            f"{target} is not a pointatlas results file (no 'pointatlas_schema' attribute)."
        )
    return ds
