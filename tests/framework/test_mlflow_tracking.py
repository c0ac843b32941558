"""``tracking=mlflow``: each run mirrored into an MLflow store (params, metrics, results.nc),
failed runs recorded FAILED, sweeps under a parent run, a clear refusal without mlflow."""
import importlib.util
import os
import subprocess
import sys

import pytest

import pointatlas
from pointatlas.errors import ConfigError
from pointatlas.mlflow_tracking import (MISSING_MLFLOW, MlflowTracking, check_tracking, flatten,
                                        run_params, tracking_uri)

needs_mlflow = pytest.mark.skipif(importlib.util.find_spec("mlflow") is None,
                                  reason="mlflow is not installed (pip install 'pointatlas[mlflow]')")
PLATE = ["experiment=shell_plate", "source.n_points=121", "study.write_vtp=false"]
#: a point load far off the plate: accepted at start-up, refused once the surface is known
OFF_SURFACE = "physics.loads=[{kind: point, at: [100.0, 0.0, 0.0], force: [0.0, 0.0, -50.0]}]"


@pytest.fixture(scope="module")
def quiet_env():
    """No usage telemetry from MLflow, and no store chosen by the environment: the runs use
    the store their command line names (pointatlas itself allows MLflow's file store)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("MLFLOW_DISABLE_TELEMETRY", "true")
        mp.delenv("MLFLOW_TRACKING_URI", raising=False)
        mp.delenv("MLFLOW_ALLOW_FILE_STORE", raising=False)
        yield


def store_runs(uri):
    """(client, runs) of the MLflow store at ``uri`` (all experiments)."""
    from mlflow.tracking import MlflowClient

    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("MLFLOW_ALLOW_FILE_STORE", "true")
        client = MlflowClient(tracking_uri=uri)
        ids = [e.experiment_id for e in client.search_experiments()]
        return client, client.search_runs(ids)


@pytest.fixture(scope="module")
def tracked(tmp_path_factory, run_cli, quiet_env):
    cwd = tmp_path_factory.mktemp("tracked")
    uri = f"file://{cwd}/mlruns"
    proc = run_cli("pointatlas", *PLATE, f"outputs_root={cwd}/outputs", "tracking=mlflow",
                   f"tracking_uri={uri}", cwd=cwd)
    assert proc.returncode == 0, proc.stderr
    (results,) = (cwd / "outputs" / "runs").glob("*/*/results.nc")
    return cwd, uri, results


@needs_mlflow
def test_run_is_mirrored_with_params_metrics_and_results(tracked, tmp_path):
    cwd, uri, results = tracked
    client, runs = store_runs(uri)
    assert len(runs) == 1
    run = runs[0]
    ds = pointatlas.open_run(results)
    assert run.info.status == "FINISHED" and run.info.run_name == ds.attrs["run_id"]
    assert client.get_experiment(run.info.experiment_id).name == "shell_plate"
    params = run.data.params
    assert params["experiment"] == "shell_plate" and params["source.n_points"] == "121"
    assert params["source"] == "square_plate" and params["study"] == "shell"
    assert params["physics.poisson_ratio"] == "0.3" and params["tracking"] == "mlflow"
    expected = float(ds["displacement"])
    assert run.data.metrics["displacement"] == pytest.approx(expected, rel=1e-9, abs=0)
    assert "time_solve" in run.data.metrics
    assert [a.path for a in client.list_artifacts(run.info.run_id)] == ["results.nc"]
    local = client.download_artifacts(run.info.run_id, "results.nc", str(tmp_path))
    assert open(local, "rb").read() == results.read_bytes()
    assert run.data.tags["pointatlas.run_dir"] == str(results.parent.resolve())
    assert not (cwd / "mlruns" / "0" / run.info.run_id).exists()  # not the default experiment


@needs_mlflow
def test_failed_run_is_recorded_failed_in_the_default_store(tmp_path, run_cli, quiet_env):
    proc = run_cli("pointatlas", *PLATE, OFF_SURFACE, f"outputs_root={tmp_path}/outputs",
                   "tracking=mlflow", "tracking_experiment=plates", cwd=tmp_path)
    assert proc.returncode == 1 and "off the surface" in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr
    client, runs = store_runs(f"file://{tmp_path}/mlruns")  # default: ./mlruns
    assert [r.info.status for r in runs] == ["FAILED"]
    run = runs[0]
    assert client.get_experiment(run.info.experiment_id).name == "plates"
    assert "off the surface" in run.data.tags["pointatlas.error"]
    assert run.data.params["source.n_points"] == "121" and not run.data.metrics
    assert [a.path for a in client.list_artifacts(run.info.run_id)] == ["error.txt"]


def test_tracking_none_is_the_default_and_writes_no_store(tmp_path, run_cli, quiet_env):
    proc = run_cli("pointatlas", *PLATE, f"outputs_root={tmp_path}/outputs", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert list((tmp_path / "outputs" / "runs").glob("*/*/results.nc"))
    assert not (tmp_path / "mlruns").exists() and not (tmp_path / "mlflow.db").exists()
    assert "MLflow" not in proc.stderr


@needs_mlflow
def test_sweep_jobs_are_children_of_a_parent_run(tmp_path, run_cli, quiet_env):
    proc = run_cli("pointatlas", "-m", "experiment=shell_plate", "study.write_vtp=false",
                   "source.n_points=121,144",
                   f"outputs_root={tmp_path}/outputs", "tracking=mlflow",
                   f"tracking_uri={tmp_path}/store", cwd=tmp_path)  # a plain path
    assert proc.returncode == 0, proc.stderr
    _, runs = store_runs(f"file://{tmp_path}/store")
    (parent,) = [r for r in runs if r.info.run_name.startswith("sweep ")]
    children = [r for r in runs if r is not parent]
    assert parent.info.status == "FINISHED"
    assert sorted(r.data.params["source.n_points"] for r in children) == ["121", "144"]
    assert {r.data.tags["mlflow.parentRunId"] for r in children} == {parent.info.run_id}
    assert all(r.info.status == "FINISHED" and "displacement" in r.data.metrics
               for r in children)


# -- without mlflow -------------------------------------------------------------------------

def test_check_refuses_tracking_mlflow_without_mlflow(monkeypatch):
    monkeypatch.setitem(sys.modules, "mlflow", None)  # `import mlflow` raises ImportError
    with pytest.raises(ConfigError) as info:
        check_tracking({"tracking": "mlflow"})
    assert str(info.value) == MISSING_MLFLOW
    assert str(info.value) == "tracking=mlflow needs mlflow: pip install 'pointatlas[mlflow]'"
    check_tracking({"tracking": "none"})  # nothing to import
    check_tracking({})


def test_callback_refuses_at_start_with_one_line(monkeypatch, capsys):
    from omegaconf import OmegaConf

    monkeypatch.setitem(sys.modules, "mlflow", None)
    with pytest.raises(SystemExit) as info:
        MlflowTracking().on_run_start(config=OmegaConf.create({"tracking": "mlflow"}))
    assert info.value.code == 2
    assert capsys.readouterr().err == f"pointatlas: error: {MISSING_MLFLOW}\n"


def test_cli_refuses_before_any_work_without_mlflow(tmp_path):
    code = ("import sys; sys.modules['mlflow'] = None\n"
            "from pointatlas.cli import main\n"
            f"main({[*PLATE, f'outputs_root={tmp_path}/outputs', 'tracking=mlflow']!r})\n")
    env = {**os.environ, "HYDRA_FULL_ERROR": "0", "PYTHONWARNINGS": "ignore"}
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300, env=env)
    assert proc.returncode == 2
    assert proc.stderr.strip() == f"pointatlas: error: {MISSING_MLFLOW}"
    assert not (tmp_path / "outputs" / "runs").exists() and not (tmp_path / "mlruns").exists()


def test_misspelt_tracking_value_lists_the_choices(tmp_path, run_cli):
    proc = run_cli("pointatlas", *PLATE, "tracking=mlfow", f"outputs_root={tmp_path}/o",
                   cwd=tmp_path)
    assert proc.returncode == 2 and "expected one of [none, mlflow]" in proc.stderr
    assert "Traceback" not in proc.stderr


@needs_mlflow
def test_sweep_with_a_failed_job_ends_its_parent_failed(tmp_path, monkeypatch, quiet_env):
    from omegaconf import OmegaConf

    from pointatlas.mlflow_tracking import JOB, mirror_run

    monkeypatch.setenv("MLFLOW_ALLOW_FILE_STORE", "true")  # restored after the test
    config = OmegaConf.create({
        "tracking": "mlflow", "tracking_uri": str(tmp_path / "store"), "tracking_experiment": "",
        "hydra": {"sweep": {"dir": str(tmp_path / "multirun" / "12-00")},
                  "runtime": {"choices": {"experiment": "demo"}}, "overrides": {"task": ["a=1,2"]}}})
    callback = MlflowTracking()
    callback.on_multirun_start(config)
    ended = {"ok": {"metrics": {"x": 1.0}}, "bad": {"error": "boom"}}
    try:
        for run_id, outcome in ended.items():
            callback.on_job_start(config)
            assert mirror_run(config, run_id=run_id, run_dir=tmp_path, experiment="demo",
                              choices={}, overrides=[], **outcome)
    finally:
        JOB.clear()
    callback.on_multirun_end(config)
    _, runs = store_runs(f"file://{tmp_path}/store")
    status = {r.info.run_name: r.info.status for r in runs}
    assert status == {"ok": "FINISHED", "bad": "FAILED", "sweep multirun/12-00": "FAILED"}


@needs_mlflow
def test_store_that_cannot_be_written_is_a_warning_not_a_failure(tmp_path, caplog, monkeypatch,
                                                                  quiet_env):
    from pointatlas.mlflow_tracking import mirror_run

    monkeypatch.setenv("MLFLOW_ALLOW_FILE_STORE", "true")  # restored after the test
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory\n")
    with caplog.at_level("WARNING", logger="pointatlas.tracking"):
        mlflow_run = mirror_run({"tracking": "mlflow", "tracking_uri": str(blocker / "mlruns")},
                                run_id="r1", run_dir=tmp_path, experiment="demo",
                                choices={}, overrides=[], metrics={"x": 1.0})
    assert mlflow_run is None
    assert "run r1 was not fully recorded in MLflow" in caplog.text


@needs_mlflow
def test_database_store_needs_sqlalchemy(monkeypatch):
    monkeypatch.setitem(sys.modules, "sqlalchemy", None)
    with pytest.raises(ConfigError, match="needs the full mlflow: pip install mlflow"):
        check_tracking({"tracking": "mlflow", "tracking_uri": "sqlite:///mlflow.db"})


# -- helpers ----------------------------------------------------------------------------------

def test_tracking_uri_defaults(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("MLFLOW_TRACKING_URI", raising=False)
    assert tracking_uri({}) == (tmp_path / "mlruns").resolve().as_uri()
    assert tracking_uri({"tracking_uri": "store"}) == (tmp_path / "store").resolve().as_uri()
    monkeypatch.setenv("MLFLOW_TRACKING_URI", "http://localhost:5000")
    assert tracking_uri({}) == "http://localhost:5000"
    assert tracking_uri({"tracking_uri": "file:///x/mlruns"}) == "file:///x/mlruns"


def test_params_are_dotted_and_spelt_like_overrides():
    config = {"seed": 3, "quiet": False, "source": {"n_points": 121, "radius": 1.5,
                                                    "at": [0.0, 1.0], "path": None}}
    assert flatten(config) == {"seed": "3", "quiet": "false", "source.n_points": "121",
                               "source.radius": "1.5", "source.at": "[0.0, 1.0]",
                               "source.path": "null"}
    params = run_params(config, {"source": "sphere", "approximant": None,
                                 "hydra/launcher": "basic"}, "demo")
    assert params["source"] == "sphere" and params["experiment"] == "demo"
    assert "approximant" not in params and "hydra/launcher" not in params
