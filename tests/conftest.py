"""Shared test set-up: off-screen plotting, no stray outputs in the working tree."""
import os

os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")

import subprocess
import sys
from pathlib import Path

import pytest

BIN = Path(sys.executable).parent


def _run_cli(cmd: str, *args: str, cwd: Path, timeout: float = 600) -> subprocess.CompletedProcess:
    """Run one of the project's console scripts in a subprocess, as a user would. Every
    results file a successful ``pointatlas`` run writes is checked for CF units (UDUNITS
    strings on every variable and coordinate)."""
    import time

    env = {**os.environ, "MPLBACKEND": "Agg", "HYDRA_FULL_ERROR": "0", "PYTHONWARNINGS": "ignore"}
    started = time.time()
    out = subprocess.run([str(BIN / cmd), *args], cwd=cwd, capture_output=True, text=True,
                         timeout=timeout, env=env)
    if cmd == "pointatlas" and out.returncode == 0:
        roots = [Path(cwd)] + [Path(a.split("=", 1)[1]) for a in args
                               if a.startswith(("outputs_root=", "hydra.sweep.dir=",
                                                "hydra.run.dir="))]
        for root in roots:
            root = root if root.is_absolute() else Path(cwd) / root
            for path in root.rglob("results.nc") if root.is_dir() else []:
                if path.stat().st_mtime >= started - 1:
                    assert_cf_units(path)
    return out


def assert_cf_units(path: Path) -> None:
    """Every variable and coordinate of a results file has UDUNITS-parseable ``units``."""
    import netCDF4
    from cf_units import Unit

    bad = []
    with netCDF4.Dataset(path) as nc:
        for name, var in nc.variables.items():
            units = getattr(var, "units", None)
            try:
                Unit(units)
            except (ValueError, TypeError):
                bad.append(f"{name}: {units!r}")
    assert not bad, f"{path}: units that are not UDUNITS strings: {bad}"


@pytest.fixture(scope="session")
def run_cli():
    return _run_cli
