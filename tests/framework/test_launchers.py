"""Sweeps through Hydra's joblib and submitit_local launchers, recorded in the catalog."""
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
    assert list(ds["source.n_points"].values) == [300, 400]
    assert ds["n_points"].values.tolist() == [300, 400]
