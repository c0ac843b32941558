"""Start-up overhead of pointatlas: `import pointatlas` and `pointatlas --help` (issue 2).

Usage: python benchmarks/bench_startup.py [out.nc]     (targets: import < 0.5 s, --help < 2 s)
Prints a table (best and median of several runs, wall seconds) and writes a netCDF file.
"""
from __future__ import annotations

import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import xarray as xr

BIN = Path(sys.executable).parent
COMMANDS = {
    "import_pointatlas": [sys.executable, "-c", "import pointatlas"],
    "pointatlas_help": [str(BIN / "pointatlas"), "--help"],
}
TARGETS = {"import_pointatlas": 0.5, "pointatlas_help": 2.0}


def timed(cmd: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True)
    return time.perf_counter() - t0


def main(out: str = str(Path(__file__).parent / "results" / "bench_startup.nc"), repeat: int = 5) -> None:
    names = list(COMMANDS)
    for cmd in COMMANDS.values():  # warm the file-system and bytecode caches once
        timed(cmd)
    samples = np.array([[timed(COMMANDS[n]) for _ in range(repeat)] for n in names])
    print(f"{'command':<20} {'best s':>8} {'median s':>9} {'target s':>9}")
    for name, row in zip(names, samples):
        print(f"{name:<20} {row.min():8.3f} {statistics.median(row):9.3f} {TARGETS[name]:9.1f}")
    ds = xr.Dataset(
        {"wall_time": (("command", "repeat"), samples, {"long_name": "wall time", "units": "s"}),
         "target": (("command",), [TARGETS[n] for n in names], {"long_name": "target", "units": "s"})},
        coords={"command": ("command", names, {"long_name": "command", "units": "1"}),
                "repeat": ("repeat", np.arange(repeat), {"long_name": "repetition", "units": "1"})},
        attrs={"title": "pointatlas start-up overhead"},
    )
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(*sys.argv[1:2])
