"""`pointatlas` end to end: runs, results, catalog, and clear errors for bad input."""
import json
import sqlite3

import numpy as np
import pytest

import pointatlas
from pointatlas.results import REQUIRED_ATTRS



def catalog_rows(root):
    with sqlite3.connect(root / "catalog.sqlite") as conn:
        conn.row_factory = sqlite3.Row
        return [dict(r) for r in conn.execute("SELECT * FROM runs")]


@pytest.fixture(scope="module")
def default_run(tmp_path_factory, run_cli):
    cwd = tmp_path_factory.mktemp("default")
    proc = run_cli("pointatlas", "experiment=swiss_roll_isomap", "source.n_points=1000", "seed=3", f"hydra.run.dir={cwd}/run", cwd=cwd)
    return cwd, proc


def test_default_run_writes_results_with_provenance(default_run):
    cwd, proc = default_run
    assert proc.returncode == 0, proc.stderr
    ds = pointatlas.open_run(cwd / "run")  # hydra.run.dir honoured
    for attr in REQUIRED_ATTRS:
        assert attr in ds.attrs, attr
    assert ds.attrs["status"] == "completed" and ds.attrs["seed"] == 3
    assert json.loads(ds.attrs["overrides"])[:2] == ["experiment=swiss_roll_isomap", "source.n_points=1000"]
    assert "n_points: 1000" in ds.attrs["config"]
    assert "embedder=isomap" in ds.attrs["source"]
    assert ds.sizes["point"] == 1000 and ds.sizes["latent"] == 2
    for name, var in ds.variables.items():
        assert "long_name" in var.attrs and "units" in var.attrs, name
    # Isomap unrolls the swiss roll: the embedding recovers its intrinsic coordinates
    assert float(ds["parameter_correlation"]) > 0.95
    assert (cwd / "run" / ".hydra" / "config.yaml").exists()


def test_default_run_is_in_the_catalog(default_run):
    cwd, _ = default_run
    rows = catalog_rows(cwd / "outputs")
    assert [r["status"] for r in rows] == ["completed"]


def test_same_seed_same_results(default_run, tmp_path, run_cli):
    cwd, _ = default_run
    proc = run_cli("pointatlas", "experiment=swiss_roll_isomap", "source.n_points=1000", "seed=3", f"hydra.run.dir={tmp_path}/run", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    a, b = pointatlas.open_run(cwd / "run"), pointatlas.open_run(tmp_path / "run")
    np.testing.assert_array_equal(a["points"].values, b["points"].values)


def test_misspelt_key_fails_before_work_listing_valid_keys(tmp_path, run_cli):
    proc = run_cli("pointatlas", "embedder=isomap", "embedder.n_neigbors=12", cwd=tmp_path)
    assert proc.returncode == 2
    assert "Unknown config key 'embedder.n_neigbors'" in proc.stderr
    assert "n_neighbors" in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "outputs" / "runs").exists()
    assert [r["status"] for r in catalog_rows(tmp_path / "outputs")] == ["rejected"]


def test_unknown_plugin_lists_installed(tmp_path, run_cli):
    proc = run_cli("pointatlas", "embedder=isomapp", cwd=tmp_path)
    assert proc.returncode == 2
    assert "No embedder plugin named 'isomapp'" in proc.stderr and "isomap" in proc.stderr


def test_wrong_type_is_named(tmp_path, run_cli):
    proc = run_cli("pointatlas", "seed=abc", cwd=tmp_path)
    assert proc.returncode == 2 and "seed=abc" in proc.stderr and "Integer" in proc.stderr


def test_missing_input_file_is_refused_and_recorded_as_rejected(tmp_path, run_cli):
    proc = run_cli("pointatlas", "source=file", f"source.path={tmp_path}/nope.npz", cwd=tmp_path)
    assert proc.returncode == 2  # refused at start-up: no run directory
    assert "nope.npz" in proc.stderr and "Traceback" not in proc.stderr
    rows = catalog_rows(tmp_path / "outputs")
    assert rows[0]["status"] == "rejected" and "nope.npz" in rows[0]["error"]
    assert not list((tmp_path / "outputs").rglob("results.nc"))
    assert not (tmp_path / "outputs" / "runs").exists()


def test_third_party_plugin_runs_by_name(tmp_path, run_cli):
    pytest.importorskip("pointatlas_spectral", reason="examples/third_party_plugin not installed")
    proc = run_cli("pointatlas", "experiment=swiss_roll_isomap", "embedder=spectral", "embedder.n_neighbors=12",
                   "source.n_points=500", f"hydra.run.dir={tmp_path}/run", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    ds = pointatlas.open_run(tmp_path / "run")
    assert "embedder=spectral (pointatlas-spectral 0.1.0)" in ds.attrs["source"]
    assert ds["embedding"].shape == (500, 2)
    assert float(ds["trustworthiness"]) > 0.9


def test_help_lists_groups(tmp_path, run_cli):
    proc = run_cli("pointatlas", "--help", cwd=tmp_path)
    assert proc.returncode == 0
    for group in ("source", "embedder", "study", "experiment", "sweep"):
        assert f"{group}:" in proc.stdout


def test_experiment_runs_unchanged_on_a_point_file(tmp_path, run_cli):
    X = np.random.default_rng(0).normal(size=(700, 3))
    np.savez(tmp_path / "cloud.npz", points=X / np.linalg.norm(X, axis=1, keepdims=True))
    proc = run_cli("pointatlas", "experiment=swiss_roll_isomap", "source=file",
                   f"source.path={tmp_path}/cloud.npz",
                   f"hydra.run.dir={tmp_path}/run", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert pointatlas.open_run(tmp_path / "run").sizes["point"] == 700


def test_no_arguments_runs_the_sphere_willmore_default(tmp_path, run_cli):
    proc = run_cli("pointatlas", "source.n_points=1500", f"hydra.run.dir={tmp_path}/run", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    ds = pointatlas.open_run(tmp_path / "run")
    assert ds.attrs["experiment"] == "sphere_willmore"
    assert float(ds["relative_error_area"]) < 1e-3
    assert float(ds["relative_error_willmore_energy"]) < 1e-2
