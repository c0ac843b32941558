"""`pointatlas` after a kill, a broken catalog or a mistake (issue 15): every run ends in the
catalog as what it is, and bad input gets one line with the fix and leaves nothing behind."""
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

import pointatlas
from pointatlas.catalog import Catalog

from .test_cli import catalog_rows

def _spawn(tmp_path, *args):
    bin_dir = Path(sys.executable).parent
    env = {**os.environ, "HYDRA_FULL_ERROR": "0", "PYTHONWARNINGS": "ignore"}
    return subprocess.Popen([str(bin_dir / "pointatlas"), *args], cwd=tmp_path, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_for(condition, timeout=120.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.05)
    return False


def _rows(root):
    path = root / "catalog.sqlite"
    if not path.exists():
        return []
    try:
        return Catalog(path).runs()
    except sqlite3.Error:
        return []


def one_line(stderr: str) -> str:
    lines = [line for line in stderr.strip().splitlines() if line.startswith("pointatlas")]
    assert "Traceback" not in stderr, stderr
    assert len(lines) == 1, stderr
    return lines[0]


def test_a_run_killed_while_it_works_reads_as_died(tmp_path):
    proc = _spawn(tmp_path, "source.n_points=20000", f"hydra.run.dir={tmp_path}/run")
    assert _wait_for(lambda: (tmp_path / "run" / "run.json").exists())
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    (record,) = _rows(tmp_path / "outputs")
    assert record.recorded_status == "running" and record.status == "died"
    assert record.pid == proc.pid and record.path == str(tmp_path / "run")


def test_a_run_killed_during_start_up_has_a_row(tmp_path):
    proc = _spawn(tmp_path, "source.n_points=20000", f"hydra.run.dir={tmp_path}/run")
    assert _wait_for(lambda: bool(_rows(tmp_path / "outputs")), timeout=30)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    (record,) = _rows(tmp_path / "outputs")
    assert record.status == "died" and not (tmp_path / "run" / "results.nc").exists()


@pytest.mark.parametrize("args,expected", [
    (["seed=-1"], "seed=-1 is invalid"),
    (["seed=99999999999999999999999"], "seed=99999999999999999999999 is invalid"),
    (["source.n_points=-5"], "source.n_points=-5 is invalid"),
    (["-m", "source.n_points=1000,-5"], "source.n_points=-5 is invalid"),
    (["~experiment", "study=embedding", "embedder.n_neigbors=3"],
     "Unknown config key 'embedder.n_neigbors'"),
    (["outputs_root=afile"], "outputs_root='afile' is a file"),
])
def test_bad_values_are_refused_at_start_up_leaving_nothing(tmp_path, run_cli, args, expected):
    (tmp_path / "afile").write_text("not a directory")
    proc = run_cli("pointatlas", *args, f"hydra.run.dir={tmp_path}/run",
                   f"hydra.sweep.dir={tmp_path}/sweep", cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert expected in one_line(proc.stderr)
    assert not (tmp_path / "run").exists() and not (tmp_path / "sweep").exists()


def test_a_geometry_error_is_refused_before_any_work(tmp_path, run_cli):
    proc = run_cli("pointatlas", "source=torus", "source.r=2.0", "source.R=1.0",
                   f"hydra.run.dir={tmp_path}/run", cwd=tmp_path)
    assert proc.returncode == 2 and not (tmp_path / "run").exists()
    assert one_line(proc.stderr).startswith("pointatlas: error: source.r=2.0 is invalid")


def test_a_sweep_lists_the_jobs_that_did_not_finish_and_goes_on(tmp_path, run_cli):
    proc = run_cli("pointatlas", "-m", "~experiment", "study=embedding", "embedder=pca",
                   "source.n_points=300", "embedder.n_components=2,9,1",
                   f"hydra.sweep.dir={tmp_path}/sweep", cwd=tmp_path)
    assert proc.returncode == 1
    assert "1 of 3 runs did not finish" in proc.stderr and "job 1 " in proc.stderr
    assert "pointatlas '~experiment=null' study=embedding embedder=pca source.n_points=300 " \
           "embedder.n_components=9" in proc.stderr
    statuses = sorted(r.status for r in _rows(tmp_path / "outputs"))
    assert statuses == ["completed", "completed", "failed"]
    assert (tmp_path / "sweep" / "2" / "results.nc").exists()  # the job after the failure ran


def test_a_killed_sweep_worker_is_reported_and_recorded(tmp_path):
    proc = _spawn(tmp_path, "-m", "source.n_points=6000,6001,6002", "hydra/launcher=local_parallel",
                  f"hydra.sweep.dir={tmp_path}/sweep")
    parent = proc.pid

    def a_worker_runs():
        return [r for r in _rows(tmp_path / "outputs") if r.pid not in (None, parent)
                and r.status == "running"]

    assert _wait_for(a_worker_runs)
    victim = a_worker_runs()[0]
    os.kill(victim.pid, signal.SIGKILL)
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 1
    assert "runs did not finish" in stderr and "Rerun just those with:" in stderr
    by_id = {r.id: r for r in _rows(tmp_path / "outputs")}
    assert by_id[victim.id].status == "died"
    assert {r.status for r in by_id.values()} <= {"completed", "died"}
    finished = [r for r in by_id.values() if r.status == "completed"]
    for record in finished:
        assert pointatlas.open_run(record.path).attrs["status"] == "completed"
    jobs = json.loads((tmp_path / "sweep" / "jobs.json").read_text())["jobs"]
    assert stderr.count("\n  pointatlas ") == len(jobs) - len(finished)


def test_a_corrupt_catalog_is_repaired_from_the_run_directories(tmp_path, run_cli):
    (tmp_path / "outputs").mkdir()
    (tmp_path / "outputs" / "catalog.sqlite").write_bytes(b"\0garbage" * 64)
    proc = run_cli("pointatlas", "~experiment", "study=embedding", "embedder=pca",
                   "source.n_points=300", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.count("pointatlas-runs repair") == 1
    listing = run_cli("pointatlas-runs", "list", cwd=tmp_path)
    assert listing.returncode == 1 and "repair" in one_line(listing.stderr)
    repair = run_cli("pointatlas-runs", "repair", cwd=tmp_path)
    assert repair.returncode == 0 and "1 completed" in repair.stdout
    (record,) = _rows(tmp_path / "outputs")
    ds = pointatlas.open_run(record.path)
    assert record.status == "completed" and record.id == ds.attrs["run_id"]
    assert record.metrics["stress"] == pytest.approx(float(ds["stress"]))
    assert list((tmp_path / "outputs").glob("catalog.sqlite.damaged-*"))


def test_gc_removes_what_killed_writes_left(tmp_path, run_cli):
    run_dir = tmp_path / "outputs" / "runs" / "x"
    run_dir.mkdir(parents=True)
    (run_dir / ".results.nc.k3j4.tmp").write_bytes(b"x" * 100)
    (run_dir / "results.nc").write_bytes(b"")
    proc = run_cli("pointatlas-runs", "gc", cwd=tmp_path)
    assert proc.returncode == 0 and "removed 1 " in proc.stdout
    assert not (run_dir / ".results.nc.k3j4.tmp").exists() and (run_dir / "results.nc").exists()


@pytest.mark.parametrize("content", [b"", b"CDF\x01garbage" * 10])
def test_a_corrupt_results_file_is_one_line(tmp_path, run_cli, content):
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "results.nc").write_bytes(content)
    with pytest.raises(pointatlas.InputError, match="results.nc (is empty|is not a readable)"):
        pointatlas.open_run(tmp_path / "run")
    proc = run_cli("pointatlas-report", str(tmp_path / "run"), cwd=tmp_path)
    assert proc.returncode == 1 and "results.nc" in one_line(proc.stderr)
    assert not (tmp_path / "run" / "report.html").exists()


def test_gc_finds_run_directories_outside_the_root_through_the_catalog(tmp_path, run_cli):
    proc = run_cli("pointatlas", "~experiment", "study=embedding", "embedder=pca",
                   "source.n_points=300", f"hydra.run.dir={tmp_path}/elsewhere", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    (tmp_path / "elsewhere" / ".results.nc.x1y2.tmp").write_bytes(b"x")
    gc = run_cli("pointatlas-runs", "gc", cwd=tmp_path)
    assert gc.returncode == 0 and "removed 1 " in gc.stdout
    assert not (tmp_path / "elsewhere" / ".results.nc.x1y2.tmp").exists()
