"""Results I/O: every run writes one CF-style netCDF file, atomically.

A results file is an xarray Dataset with named dims and coords, ``long_name``/``units`` on
every variable, scalar metrics as 0-d variables and the provenance as global attrs
(see :data:`REQUIRED_ATTRS`). Writing goes to a temporary file in the same directory that
is renamed over ``results.nc`` only when complete, so a killed run never leaves a
truncated file; the temporary files a killed write leaves behind (``.results.nc.*.tmp``) are
removed by the next run in that directory (:func:`remove_partial_files`) and by
``pointatlas-runs gc``. Results files get the permissions of the user's umask, like every
other file a run writes.

Large variables (at least :data:`CHUNK_MIN_ELEMENTS` elements) are stored in netCDF4 chunks of
about :data:`CHUNK_BYTES` (see :func:`chunk_shape`), so ``open_run(path, lazy=True)`` reads a
10^6-point field piece by piece with dask instead of whole; small variables stay contiguous.
"""
from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .errors import ConfigError, InputError, SchemaError
from .run_files import RESULTS_NAME

SCHEMA_VERSION = 1
REQUIRED_ATTRS = (
    "Conventions", "title", "source", "history", "config", "overrides", "git_commit",
    "seed", "hostname", "wall_time_s", "status",
)
CHUNK_BYTES = 2**20  # bytes per netCDF chunk of a large variable (1 MiB)
CHUNK_MIN_ELEMENTS = 2**16  # variables with fewer elements are stored contiguously
_CHUNKED_KINDS = "biufmM"  # numbers, booleans, datetimes and timedeltas (not strings)
_COMPRESSION_KEYS = ("zlib", "compression", "szip", "bzip2", "blosc", "zstd")


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
    the new one, and at worst a ``.<name>.*.tmp`` leftover (:func:`remove_partial_files`).

    Each variable is written with :func:`storage_encoding`: large ones chunked (~1 MiB chunks,
    uncompressed unless its encoding asks otherwise), small ones contiguous."""
    path = Path(path)
    out = ds.copy()  # new Variable objects, so the caller's encodings are left alone
    for var in out.variables.values():
        var.encoding = storage_encoding(var)
    tmp = _temporary_name(path)
    try:
        out.to_netcdf(tmp, engine="netcdf4")
        _publish(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def chunk_shape(shape: tuple[int, ...], itemsize: int,
                target_bytes: int = CHUNK_BYTES) -> tuple[int, ...]:
    """Chunk sizes (elements per dimension) for an array of ``shape`` whose elements take
    ``itemsize`` bytes each, so that one chunk holds at most ``target_bytes`` bytes.

    The first dimension is cut into runs of ``target_bytes // (bytes of one slice along
    it)`` slices and the other dimensions are whole; when one such slice alone is larger
    than ``target_bytes``, the first chunk size is 1 and the rule is applied to the remaining
    dimensions. A chunk never exceeds its dimension and holds at least one element (so
    elements larger than ``target_bytes`` get chunks of one element). Dimensions must be
    at least 1 long (HDF5 has no empty chunks). Example: float64 ``(2_000_000,)`` ->
    ``(131072,)`` (exactly 1 MiB); ``(10**6, 3)`` -> ``(43690, 3)``.
    """
    if not shape:
        return ()
    first, rest = int(shape[0]), tuple(int(n) for n in shape[1:])
    slice_bytes = itemsize * math.prod(rest)
    if slice_bytes > target_bytes:
        return (1, *chunk_shape(rest, itemsize, target_bytes))
    return (max(1, min(first, target_bytes // max(slice_bytes, 1))), *rest)


def storage_encoding(var: xr.Variable) -> dict:
    """The encoding ``var`` is written with (a new dict; ``var.encoding`` is not changed).

    Storage choices already in ``var.encoding`` are respected: valid ``chunksizes``, and
    ``contiguous=True`` set by the caller (not read from a file). Stale ones are dropped:
    ``chunksizes`` that do not fit the variable's shape, or any chunk layout read from a
    file whose variable has since changed shape (``original_shape``). Otherwise a numeric
    variable of at least :data:`CHUNK_MIN_ELEMENTS` elements gets ``chunksizes`` from
    :func:`chunk_shape` (about :data:`CHUNK_BYTES` bytes per chunk, by its on-disk dtype)
    and ``zlib=False`` unless a compression is already set; smaller ones stay contiguous.
    """
    enc = dict(var.encoding)
    if not _chunks_fit(enc, var):
        enc.pop("chunksizes", None)
    if enc.get("original_shape", var.shape) != var.shape:
        enc.pop("contiguous", None)
    large = var.size >= CHUNK_MIN_ELEMENTS and var.dtype.kind in _CHUNKED_KINDS
    if not large or enc.get("chunksizes") is not None:
        return enc
    if enc.get("contiguous") and "original_shape" not in enc:
        return enc  # the caller asked for contiguous storage
    enc.pop("contiguous", None)
    enc["chunksizes"] = chunk_shape(var.shape, _disk_itemsize(var, enc))
    if not any(key in enc for key in _COMPRESSION_KEYS):
        enc["zlib"] = False
    return enc


def _chunks_fit(enc: dict, var: xr.Variable) -> bool:
    """Whether ``enc`` has no ``chunksizes`` or ones valid for ``var`` as it is now."""
    chunks = enc.get("chunksizes")
    if chunks is None:
        return True
    if enc.get("original_shape", var.shape) != var.shape or len(chunks) != var.ndim:
        return False
    return all(1 <= int(c) <= n for c, n in zip(chunks, var.shape))


def _disk_itemsize(var: xr.Variable, enc: dict) -> int:
    """Bytes per element on disk: the encoding's ``dtype`` if it has one, else the data's."""
    try:
        return np.dtype(enc.get("dtype", var.dtype)).itemsize or var.dtype.itemsize
    except TypeError:
        return var.dtype.itemsize


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


def open_run(path: str | os.PathLike, lazy: bool = False) -> xr.Dataset:
    """Open one run's results (a run directory or its ``results.nc``).

    By default the whole file is read into memory and closed. With ``lazy=True`` nothing is
    read yet: the variables are dask arrays in the file's own netCDF chunks (about 1 MiB
    for large variables, see :func:`chunk_shape`), the file stays open until
    ``ds.close()`` (or the end of a ``with open_run(..., lazy=True) as ds:`` block), and
    values are read as they are computed. Lazy opening needs dask
    (:class:`~pointatlas.errors.ConfigError` naming the install otherwise).

    Raises :class:`~pointatlas.errors.InputError` for a missing, empty or unreadable file and
    :class:`~pointatlas.errors.SchemaError` for a file written by a newer schema.
    """
    target = results_path(path)
    if lazy:
        _require_dask()
    try:
        if lazy:
            ds = xr.open_dataset(target, engine="netcdf4", chunks={})
        else:
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
    try:
        _check_schema(ds, target)
    except SchemaError:
        ds.close()
        raise
    return ds


def _require_dask() -> None:
    try:
        import dask.array  # noqa: F401
    except ImportError:
        raise ConfigError(
            "open_run(..., lazy=True) needs dask: pip install 'pointatlas[distributed]'"
        ) from None


def _check_schema(ds: xr.Dataset, target: Path) -> None:
    """SchemaError unless ``ds`` is a pointatlas results file of a schema this version reads."""
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
