"""Re-measure the headline figures of the geometry and linear-shell experiments in one run.

Every change to the atlas (chart test, repair, orientation) must leave these unchanged or
better (issue 16: "every existing geometry and shell figure unchanged or better"; issue 17:
"every shell figure ... the same value to 1e-8 relative"). Each command line runs as a user
would type it (``pointatlas …`` in a fresh outputs directory); its results.nc is read and the
figures printed with 9 significant digits, plus the patch counts and the wall time.

Usage: python benchmarks/headline_figures.py [--only NAME ...] [--out figures.json]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

GEOMETRY = ("area", "relative_error_area", "willmore_energy", "relative_error_willmore_energy",
            "total_gaussian_curvature", "relative_error_total_gaussian_curvature",
            "n_patches", "n_unaccepted_patches")
SHELL = ("displacement", "relative_error", "n_unaccepted_patches")
#: name -> (command-line overrides, result variables)
RUNS = {
    "sphere_willmore": (["experiment=sphere_willmore"], GEOMETRY),
    "sphere_willmore_random": (["experiment=sphere_willmore_random"], GEOMETRY),
    "torus": (["experiment=sphere_willmore", "source=torus"], GEOMETRY),
    "connected_pipes": (["experiment=sphere_willmore", "source=connected_pipes"], GEOMETRY),
    "shell_plate": (["experiment=shell_plate"], SHELL),
    "shell_scordelis_lo": (["experiment=shell_scordelis_lo"], SHELL),
    "shell_cylinder": (["experiment=shell_cylinder"], SHELL),
    "shell_hemisphere": (["experiment=shell_hemisphere"], SHELL),
}


def measure(name: str, overrides: list[str], variables: tuple) -> dict:
    import xarray as xr

    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        exe = str(Path(sys.executable).with_name("pointatlas"))
        out = subprocess.run([exe, *overrides,
                              f"outputs_root={tmp}"], capture_output=True, text=True, cwd=tmp)
        wall = time.perf_counter() - t0
        if out.returncode != 0:
            return {"name": name, "error": out.stderr.strip().splitlines()[-1], "wall_s": wall}
        with xr.open_dataset(next(Path(tmp).glob("runs/*/*/results.nc"))) as ds:
            row = {v: float(ds[v].values.ravel()[0]) for v in variables if v in ds}
            row["warnings"] = str(ds.attrs.get("warnings", ""))[:120]
    return {"name": name, **row, "wall_s": round(wall, 1)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", choices=sorted(RUNS), default=None)
    ap.add_argument("--out", default=None, help="also write the rows as JSON here")
    args = ap.parse_args(argv)
    rows = []
    for name in args.only or RUNS:
        overrides, variables = RUNS[name]
        row = measure(name, overrides, variables)
        rows.append(row)
        print(name, " ".join(f"{k}={v:.9g}" if isinstance(v, float) else f"{k}={v}"
                             for k, v in row.items() if k != "name"), flush=True)
    if args.out:
        Path(args.out).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
