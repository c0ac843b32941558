"""A tiny rom_linear_modes in CI: PCA reduction of a small vibration of the full model
against the modal truncation (an independent reference: the eigenproblem K φ = ω² M φ)."""
import xarray as xr


def test_tiny_rom_linear_modes(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=rom_linear_modes", "physics.n_triangles=120",
                  "study.n_modes=[1,2]", "study.steps_per_period=400",
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    ds = xr.open_dataset(next(tmp_path.glob("runs/*/*/results.nc")))
    assert float(ds["relative_error"]) < 1e-3
    assert list(ds["n_components"].values) == [1, 2]
    assert (ds["angular_frequency"].diff("mode") > 0).all()


def test_the_study_needs_an_elastic_body(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=rom_linear_modes", "physics=stokes_axisymmetric",
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode != 0 and "Traceback" not in out.stderr
    assert "physics=neo_hookean_2d" in out.stderr, out.stderr[-2000:]
