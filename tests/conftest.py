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


def _cli_env() -> dict:
    """The environment the console scripts run with in the tests."""
    return {**os.environ, "MPLBACKEND": "Agg", "HYDRA_FULL_ERROR": "0", "PYTHONWARNINGS": "ignore"}


def _run_cli(cmd: str, *args: str, cwd: Path, timeout: float = 600) -> subprocess.CompletedProcess:
    """Run one of the project's console scripts in a new process, as a user would. Every
    results file a successful ``pointatlas`` run writes is checked for CF units (UDUNITS
    strings on every variable and coordinate).

    The process is forked from a server that has the libraries imported already
    (``tests/cli_zygote.py``: the same entry point, argv, directory, environment and exit
    status, without 4.5 s of imports per run); ``POINTATLAS_TEST_SUBPROCESS=1`` runs the
    installed script itself instead, and so does any test that changed the environment
    beyond the project's own variables."""
    import time

    env = _cli_env()
    started = time.time()
    if _ZYGOTE.usable(env):
        out = _ZYGOTE.run(cmd, args, cwd=cwd, env=env, timeout=timeout)
    else:
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


class _Zygote:
    """Client of ``tests/cli_zygote.py``, started on first use, one per test process."""

    OWN_VARIABLES = ("POINTATLAS_", "HYDRA_", "MLFLOW_", "PYTEST_")

    def __init__(self):
        self.proc = None
        self.base_env = _cli_env()
        self.broken = os.environ.get("POINTATLAS_TEST_SUBPROCESS") == "1"

    def usable(self, env: dict) -> bool:
        """Whether a fork gives what a new process would: the environment differs from the
        server's only in the project's own variables (read at run time, not at import)."""
        if self.broken:
            return False
        if self.proc is None:
            self._start()
        ref = self.zygote_env
        changed = {k for k in set(env) | set(ref) if env.get(k) != ref.get(k)}
        return all(k.startswith(self.OWN_VARIABLES) or (k in self.preload_set and k not in env)
                   for k in changed)

    def _start(self) -> None:
        import tempfile

        self.home = tempfile.mkdtemp(prefix="pointatlas-zygote-")
        self.proc = subprocess.Popen([sys.executable, str(Path(__file__).with_name("cli_zygote.py"))],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                     cwd=self.home, env=self.base_env)
        ready = self._read(300)
        self.zygote_env, self.preload_set = ready["env"], ready["preload_set"]

    def _read(self, timeout: float) -> dict:
        import json
        import select

        ready, _, _ = select.select([self.proc.stdout], [], [], timeout)
        if not ready:
            raise TimeoutError
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError(f"the test fork server exited ({self.proc.wait()})")
        return json.loads(line)

    def run(self, cmd: str, args, cwd: Path, env: dict, timeout: float) -> subprocess.CompletedProcess:
        import json
        import signal
        import tempfile

        with tempfile.TemporaryDirectory(dir=self.home) as tmp:
            request = {"cmd": cmd, "argv0": str(BIN / cmd), "args": list(args), "cwd": str(cwd),
                       "env": env, "stdout": f"{tmp}/out", "stderr": f"{tmp}/err"}
            self.proc.stdin.write(json.dumps(request) + "\n")
            self.proc.stdin.flush()
            pid = self._read(60)["pid"]
            try:
                code = self._read(timeout)["returncode"]
            except TimeoutError:
                os.kill(pid, signal.SIGKILL)
                self._read(60)
                raise subprocess.TimeoutExpired([cmd, *args], timeout) from None
            text = [Path(f"{tmp}/{name}").read_text(errors="replace") for name in ("out", "err")]
        return subprocess.CompletedProcess([str(BIN / cmd), *args], code, *text)

    def close(self) -> None:
        if self.proc is not None:
            self.proc.stdin.close()
            self.proc.wait(timeout=60)
            import shutil

            shutil.rmtree(self.home, ignore_errors=True)


_ZYGOTE = _Zygote()


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
    yield _run_cli
    _ZYGOTE.close()
