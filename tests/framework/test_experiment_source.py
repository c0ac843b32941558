"""An experiment made for a generator does not cut or misconfigure a user's file (issue 16,
item 5): the file keeps every point unless source.n_points is given, and says when it cuts."""
import numpy as np

import pointatlas


def _cloud(path, n):
    X = np.random.default_rng(1).normal(size=(n, 3))
    np.savez(path, points=X / np.linalg.norm(X, axis=1, keepdims=True))


def test_an_experiment_resolution_does_not_cut_a_file(tmp_path, run_cli):
    _cloud(tmp_path / "c.npz", 2300)  # swiss_roll_isomap sets source.n_points: 2000
    proc = run_cli("pointatlas", "experiment=swiss_roll_isomap", "source=file",
                   f"source.path={tmp_path}/c.npz", f"hydra.run.dir={tmp_path}/run", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    ds = pointatlas.open_run(tmp_path / "run")
    assert ds.sizes["point"] == 2300
    assert int(ds["source_points_in_source"]) == int(ds["source_points_used"]) == 2300
    assert "sets source.n_points=2000 for its own source; not applied to source=file" in proc.stderr


def test_n_points_on_the_command_line_subsamples_and_says_so(tmp_path, run_cli):
    _cloud(tmp_path / "c.npz", 2300)
    proc = run_cli("pointatlas", "experiment=swiss_roll_isomap", "source=file",
                   f"source.path={tmp_path}/c.npz", "source.n_points=1500",
                   f"hydra.run.dir={tmp_path}/run", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    log = proc.stdout + proc.stderr
    assert "using 1500 of its 2300 points" in log and "not applied" not in log
    ds = pointatlas.open_run(tmp_path / "run")
    assert (int(ds["source_points_in_source"]), int(ds["source_points_used"])) == (2300, 1500)


def test_generator_settings_of_an_experiment_do_not_break_a_file(tmp_path, run_cli):
    _cloud(tmp_path / "c.npz", 500)
    proc = run_cli("pointatlas", "experiment=sphere_willmore_random", "source=file",
                   f"source.path={tmp_path}/c.npz", "--cfg", "job", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    import yaml

    source = yaml.safe_load(proc.stdout)["source"]
    assert "sampling" not in source and source["n_points"] is None
    assert source["path"] == f"{tmp_path}/c.npz"
