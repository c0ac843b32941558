"""A wheel works outside the checkout: it is built from a copy of the sources, installed in a
fresh virtual environment (the dependencies are lent by the test's environment, pointatlas
itself is not), and run from a folder that is not the checkout: the shipped configs and
experiments are found, and a folder named ``pointatlas`` in the working directory (a clone's
parent) does not shadow the package."""
import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

REPO = Path(__file__).resolve().parents[2]
SOURCES = ("pyproject.toml", "README.md", "framework", "plugins", "conf", "experiments")


def _run(args, cwd, env=None, timeout=600):
    out = subprocess.run([str(a) for a in args], cwd=cwd, capture_output=True, text=True,
                         timeout=timeout, env=env)
    assert out.returncode == 0, (out.stdout[-2000:], out.stderr[-3000:])
    return out


@pytest.fixture(scope="module")
def wheel_venv(tmp_path_factory):
    root = tmp_path_factory.mktemp("wheel")
    src = root / "src"
    src.mkdir()
    ignore = shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc", "*.egg-info")
    for name in SOURCES:
        (shutil.copytree if (REPO / name).is_dir() else shutil.copy2)(
            REPO / name, src / name, **({"ignore": ignore} if (REPO / name).is_dir() else {}))
    _run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation",
          "-w", root / "dist", src], cwd=root)
    wheel = next((root / "dist").glob("pointatlas-*.whl"))
    venv = root / "venv"
    _run([sys.executable, "-m", "venv", "--without-pip", venv], cwd=root)
    # lend the dependencies: every entry of this environment's site-packages but pointatlas
    lent = root / "lent"
    lent.mkdir()
    site = Path(sysconfig.get_paths()["purelib"])
    for entry in site.iterdir():
        if "pointatlas" not in entry.name.lower() and not entry.name.startswith("__editable__"):
            os.symlink(entry, lent / entry.name)
    target = next(venv.glob("lib/python*/site-packages"))
    (target / "lent.pth").write_text(f"{lent}\n")
    _run([sys.executable, "-m", "pip", "--python", venv / "bin" / "python", "install", "-q",
          "--no-deps", "--no-index", wheel], cwd=root)
    return venv, root


def test_the_wheel_ships_configs_and_experiments(wheel_venv):
    venv, root = wheel_venv
    away = root / "elsewhere"
    (away / "pointatlas").mkdir(parents=True)  # a clone's folder beside the working directory
    out = _run([venv / "bin" / "python", "-c",
                "import pointatlas, pointatlas.config as c; print(pointatlas.__file__); "
                "print(c.CONF_DIR); print(len(c.experiments())); print(len(pointatlas.plugins()))"],
               cwd=away)
    module, conf, n_experiments, n_plugins = out.stdout.split()
    assert str(venv) in module and str(venv) in conf and str(REPO) not in module
    assert int(n_experiments) == len(list((REPO / "experiments").glob("*.yaml")))
    assert int(n_plugins) > 10
    job = _run([venv / "bin" / "pointatlas", "--cfg", "job"], cwd=away)
    assert "source:" in job.stdout and "study:" in job.stdout


def test_the_wheel_runs_an_experiment(wheel_venv):
    venv, root = wheel_venv
    away = root / "run_here"
    away.mkdir()
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONWARNINGS": "ignore"}
    # the towed sphere (F = 6πμaU): a shipped experiment whose few numba kernels compile in
    # seconds in the new environment (the shell's take 80 s there, and runs_truth and the
    # shell tests run it in the checkout)
    _run([venv / "bin" / "pointatlas", "experiment=stokes_sphere_drag", "outputs_root=out"],
         cwd=away, env=env)
    ds = xr.open_dataset(next((away / "out" / "runs").glob("*/*/results.nc")))
    assert float(ds["drag_reference"]) == pytest.approx(6 * np.pi, rel=1e-12)
    assert abs(float(ds["drag"]) / float(ds["drag_reference"]) - 1) < 1e-8
