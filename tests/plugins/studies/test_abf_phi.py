"""abf_phi from the command line: a very short run in CI (the pipeline, units, finite
profiles), the whole experiment's bar as a slow test."""
import numpy as np
import pytest
import xarray as xr

SHORT = ("study.abf_steps=4000", "study.n_windows=12", "study.window_steps=1000",
         "study.window_equilibration=200", "study.n_blocks=2", "study.n_bins=24",
         "study.full_samples=20")


def test_a_short_abf_and_umbrella_run(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=abf_phi", *SHORT, f"outputs_root={tmp_path}",
                  cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    ds = xr.open_dataset(next(tmp_path.glob("runs/*/*/results.nc")))
    assert ds["free_energy_umbrella"].attrs["units"] == "kJ/mol"
    assert ds.sizes["phi"] == 24 and ds.sizes["window"] == 12
    us = ds["free_energy_umbrella"].values
    assert np.all(np.isfinite(us)) and us.min() == 0.0
    # the C7eq/C5 region (φ < 0) lies below the φ ≈ 0 barrier even after 24 ps of umbrellas
    phi = ds["phi"].values
    assert us[(phi > -170) & (phi < -60)].min() + 10 < us[np.abs(phi) < 15].max()
    assert int(ds["abf_samples"].sum()) == 4000
    assert float(ds["abf_ns"]) == pytest.approx(0.008)
    assert float(ds["abf_ns_per_day"]) > 0


@pytest.mark.slow
def test_abf_agrees_with_umbrella_sampling(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=abf_phi", f"outputs_root={tmp_path}",
                  cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    ds = xr.open_dataset(next(tmp_path.glob("runs/*/*/results.nc")))
    assert float(ds["rms_difference"]) < 2.0
    assert int(ds["n_common_bins"]) >= 60
