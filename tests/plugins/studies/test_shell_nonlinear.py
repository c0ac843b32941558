"""The nonlinear shell study from the command line: increments, monitors, resume."""
import pytest
import xarray as xr

from pointatlas import open_run

ARGS = ["experiment=shell_open_hemisphere", "source.n_points=200", "study.n_increments=2",
        "study.max_load_factor=0.1", "study.quadrature_order=4", "quiet=true"]


def test_open_hemisphere_path_and_resume(tmp_path, run_cli):
    out = tmp_path / "out"
    r = run_cli("pointatlas", *ARGS, f"outputs_root={out}", cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    run_dir = next(out.glob("runs/*/*"))
    ds = open_run(run_dir)
    assert ds["radial_displacement"].dims == ("increment", "point")
    assert list(ds["point"].values) == ["A", "B"]
    assert ds["load"].values.tolist() == pytest.approx([20.0, 40.0])
    a, b = ds["radial_displacement"].values[-1]
    # Sze et al. at P/Pmax = 0.10: A 1.499, B 1.840 (coarse model: within 10 %)
    assert a == pytest.approx(1.499, rel=0.1) and b == pytest.approx(1.840, rel=0.1)
    assert int(ds["stable"].min()) == 1
    with xr.open_dataset(run_dir / "increments.nc") as inc:
        assert inc.sizes["increment"] == 2 and "nodal_displacement" in inc
    r = run_cli("pointatlas", *ARGS[:-2], "study.max_load_factor=0.15", "study.n_increments=3",
                f"study.resume_from={run_dir}", f"outputs_root={tmp_path / 'out2'}",
                "quiet=true", cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    resumed = open_run(next((tmp_path / "out2").glob("runs/*/*")))
    assert resumed["load_factor"].values.tolist() == pytest.approx([0.1, 0.15])
