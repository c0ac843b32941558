"""rom_neo_hookean at a tiny size: the comparison's results and figures, and its refusals
(a snapshot sweep of mixed meshes, a test start far from the training set)."""
import numpy as np
import xarray as xr

TINY = ["experiment=rom_neo_hookean", "physics.n_triangles=150", "physics.n_steps=20000",
        "physics.save_every=100", "study.n_trajectories=3", "study.n_test=1",
        "study.pca_dims=[1,2,3]", "study.nonlinear=[isomap]", "study.nonlinear_dims=[1,2]",
        "study.decimation=0.02", "study.test_duration=0.05", "study.n_error_samples=8",
        "study.n_map=5", "study.n_frames=3", "study.strip_pca_dim=2", "study.n_bins=12",
        "study.n_bins_1d=40", "study.max_start_distance=1.0"]


def test_tiny_comparison_and_its_figures(run_cli, tmp_path):
    from pointatlas_studies.rom_neo_hookean import RomNeoHookean

    out = run_cli("pointatlas", *TINY, f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    ds = xr.open_dataset(next(tmp_path.glob("**/results.nc")))
    assert ds["trajectory_distance"].dims == ("method", "n_components")
    assert ds["reconstruction_error"].dims == ("method", "n_components")
    assert list(ds["method"].values) == ["pca", "isomap"]
    D = ds["trajectory_distance"].sel({"method": "pca"}).values
    e = ds["reconstruction_error"].sel({"method": "pca"}).values
    assert np.all(np.isfinite(D)) and np.all((D > 0) & (D < 0.1))
    assert np.all(np.diff(e) < 0)                  # PCA's e falls with every added mode
    e_iso = ds["reconstruction_error"].sel({"method": "isomap"}).values[:2]
    assert np.all(np.isfinite(e_iso)) and np.all(e_iso < 0.05)
    assert np.all(ds["reduced_time_reached"].sel({"method": "pca"}) >= 0.05 - 1e-12)
    assert float(ds["full_wall_per_time"]) > 0
    assert ds["strip_position"].sizes["strip_model"] == 4    # full, pca d=2, isomap d=1, 2
    figs = RomNeoHookean.report_figures(ds)
    assert len(figs) == 5 and all(f.axes for _, f in figs)


def test_a_sweep_of_mixed_meshes_is_refused(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=rom_snapshots", "physics.n_triangles=150,200",
                  "physics.n_steps=400", "physics.save_every=100", f"outputs_root={tmp_path}",
                  "-m", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    sweep = next(tmp_path.glob("multirun/*/*"))
    out = run_cli("pointatlas", *TINY, f"study.snapshots={sweep}", "study.n_test=1",
                  f"outputs_root={tmp_path / 'b'}", cwd=tmp_path)
    assert out.returncode != 0 and "Traceback" not in out.stderr
    assert "different mesh" in out.stderr


def test_a_start_far_from_the_training_set_is_refused(run_cli, tmp_path):
    out = run_cli("pointatlas", *TINY, "study.max_start_distance=1e-9",
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode != 0 and "Traceback" not in out.stderr
    assert "nearest training snapshot" in out.stderr and "max_start_distance" in out.stderr
