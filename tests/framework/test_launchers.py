"""Sweeps through Hydra's joblib and submitit_local launchers, recorded in the catalog."""
import json
import os
import sqlite3

import pytest

import pointatlas



@pytest.mark.parametrize("launcher", ["joblib", "submitit_local"])
def test_two_job_sweep_is_cataloged(tmp_path, launcher, run_cli):
    if launcher == "submitit_local":
        pytest.importorskip("hydra_plugins.hydra_submitit_launcher")
    proc = run_cli("pointatlas", "--multirun", "experiment=swiss_roll_isomap", "source.n_points=300,400", "embedder=pca",
                   f"hydra/launcher={launcher}", f"hydra.sweep.dir={tmp_path}/sweep",
                   cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-3000:]
    with sqlite3.connect(tmp_path / "outputs" / "catalog.sqlite") as conn:
        rows = conn.execute("SELECT status, overrides FROM runs").fetchall()
    assert sorted(r[0] for r in rows) == ["completed", "completed"]
    ds = pointatlas.open_sweep(tmp_path / "sweep")
    assert list(ds["source_n_points"].values) == [300, 400]
    assert ds["n_points"].values.tolist() == [300, 400]


def test_a_finished_sweep_writes_sweep_nc_with_its_id(tmp_path, run_cli):
    proc = run_cli("pointatlas", "--multirun", "experiment=swiss_roll_isomap",
                   "source.n_points=300,400", "embedder=pca", f"hydra.sweep.dir={tmp_path}/sweep",
                   cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-3000:]
    combined = tmp_path / "sweep" / "sweep.nc"
    assert combined.is_file()
    with sqlite3.connect(tmp_path / "outputs" / "catalog.sqlite") as conn:
        params = [json.loads(p) for (p,) in conn.execute("SELECT params FROM runs")]
    sweep_ids = {p.get("sweep") for p in params}
    assert len(sweep_ids) == 1 and next(iter(sweep_ids)).startswith("sweep-")
    ds = pointatlas.open_sweep(tmp_path / "sweep")  # read from sweep.nc
    assert ds.attrs["sweep_id"] in sweep_ids and ds.encoding["source"].endswith("sweep.nc")
    assert ds["n_points"].values.tolist() == [300, 400]
    # a job rerun after the sweep makes sweep.nc stale: the jobs are read again
    job = next((tmp_path / "sweep").glob("*/results.nc"))
    os.utime(job, (combined.stat().st_mtime + 10,) * 2)
    again = pointatlas.open_sweep(tmp_path / "sweep")
    assert not str(again.encoding.get("source", "")).endswith("sweep.nc")
    assert again["n_points"].values.tolist() == [300, 400]
