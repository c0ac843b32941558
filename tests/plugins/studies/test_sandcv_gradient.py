"""sandcv_gradient from the command line (the whole experiment: about 10 s), and its refusals."""
import xarray as xr


def test_sandcv_gradient_meets_its_bars(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=sandcv_gradient", f"outputs_root={tmp_path}",
                  cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    ds = xr.open_dataset(next(tmp_path.glob("runs/*/*/results.nc")))
    assert int(ds["n_accepted"]) >= 95
    assert float(ds["gradient_error"]) < 1e-6
    assert float(ds["rigid_motion_error"]) < 1e-10
    assert 1 <= int(ds["max_newton_steps"]) <= 5
    assert ds["distance"].attrs["units"] == "nm"


def test_an_unavailable_platform_is_named(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=sandcv_gradient", "study.platform=NoSuchGPU",
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode != 0 and "Traceback" not in out.stderr
    assert "platform 'NoSuchGPU' is not available" in out.stderr


def test_too_few_frames_for_the_embedding_are_refused(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=sandcv_gradient", "study.n_frames=20",
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode != 0 and "Traceback" not in out.stderr
    assert "too few" in out.stderr


def test_a_trajectory_of_another_system_is_refused(run_cli, tmp_path):
    import mdtraj
    import numpy as np

    top = mdtraj.Topology()
    res = top.add_residue("X", top.add_chain())
    for _ in range(5):
        top.add_atom("C", mdtraj.element.carbon, res)
    path = tmp_path / "other.dcd"
    mdtraj.Trajectory(np.zeros((3, 5, 3), np.float32), top).save_dcd(str(path))
    out = run_cli("pointatlas", "experiment=sandcv_gradient", f"study.trajectory={path}",
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode != 0 and "Traceback" not in out.stderr
    assert "topology does not match" in out.stderr or "cannot read trajectory" in out.stderr
