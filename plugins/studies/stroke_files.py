"""A user's stroke from a file: ``times`` (K+1,), ``shapes`` (K+1, n, 2) as (r, z) and
``velocities`` (K+1, n, 3) as (v_r, v_z, v_φ), in a netCDF file (variables of those names,
any dim names) or a NumPy ``.npz`` (arrays of those names). The last sample repeats the
first shape (a periodic stroke); nodes run top pole first."""
from __future__ import annotations

from pathlib import Path

import numpy as np

NAMES = ("times", "shapes", "velocities")


def read_stroke(path: str):
    """(times, shapes, velocities) arrays; InputError naming the problem otherwise."""
    from pointatlas.errors import InputError

    if not path:
        raise InputError("study.case=stroke_file needs study.stroke_file=<path to .nc or "
                         ".npz with times, shapes, velocities>.")
    p = Path(path).expanduser()
    if not p.is_file():
        raise InputError(f"study.stroke_file={path}: no such file. Give the path of a .nc or "
                         f".npz stroke.")
    try:
        if p.suffix == ".npz":
            with np.load(p) as f:
                data = {k: np.asarray(f[k]) for k in NAMES if k in f}
        else:
            import xarray as xr

            with xr.open_dataset(p) as f:
                data = {k: np.asarray(f[k].values) for k in NAMES if k in f}
    except Exception as exc:  # noqa: BLE001 - any unreadable file is the user's to fix
        raise InputError(f"study.stroke_file={path} cannot be read ({type(exc).__name__}: "
                         f"{exc}); give a netCDF or .npz file.") from None
    missing = [k for k in NAMES if k not in data]
    if missing:
        raise InputError(f"study.stroke_file={path} lacks {', '.join(missing)}; it needs "
                         f"times (K+1,), shapes (K+1, n, 2) and velocities (K+1, n, 3).")
    return data["times"], data["shapes"], data["velocities"]
