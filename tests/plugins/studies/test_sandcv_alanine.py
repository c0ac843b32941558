"""sandcv_alanine from the command line: a very short run in CI (the pipeline, units, the
training set's basin, refusals counted), the whole experiment's bars as a slow test."""
import numpy as np
import pytest
import xarray as xr

SHORT = ("study.n_frames=300", "study.abf_steps=3000", "study.reference_steps=3000",
         "study.min_count=2", "study.full_samples=20")


def test_a_short_sandcv_and_reference_run(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=sandcv_alanine", *SHORT,
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    ds = xr.open_dataset(next(tmp_path.glob("runs/*/*/results.nc")))
    # the short unbiased run stays in C7eq/C5: the basin to find is absent from training
    assert float(ds["training_fraction_unsampled_basin"]) == 0.0
    train = ds["training_dihedrals"].values
    assert np.mean((train[:, 0] < 0) | (train[:, 0] > 150)) == 1.0
    assert ds["free_energy_cv"].attrs["units"] == "kJ/mol"
    assert ds.sizes["xi1"] == 24 and ds.sizes["phi"] == 24
    # every step is either biased (counted in a ξ cell) or refused (counted, no bias)
    assert int(ds["cv_samples"].sum()) + int(ds["n_refused"]) <= 3000
    assert int(ds["cv_samples"].sum()) + int(ds["n_refused"]) >= 3000 - 10
    # (φ, ψ) of the manifold's configurations lie where the training frames are
    cells = ds["cv_cell_dihedrals"].values.reshape(-1, 2)
    cells = cells[np.isfinite(cells[:, 0])]
    assert len(cells) > 50 and np.mean((cells[:, 0] < 0) | (cells[:, 0] > 150)) > 0.95
    assert int(ds["phi_psi_samples"].sum()) == 3000
    A = ds["free_energy_cv"].values
    assert np.nanmin(A) == 0.0
    assert float(ds["abf_ns_per_day"]) > 0 and float(ds["reference_ns_per_day"]) > 0
    # where A(ξ) has a C7eq minimum, it maps to (φ, ψ) in that basin (φ < 0). 3 000 biased
    # steps do not always sample it: in a fresh-clone CI run under load it was NaN (the
    # trajectory differed from the quiet runs, which give (−70°, 103°)); the full
    # experiment's bar is the slow test below
    c7eq = ds["sandcv_minimum"].sel(basin="C7eq").values
    assert np.all(np.isfinite(c7eq)) == np.any(np.isfinite(c7eq))
    assert not np.isfinite(c7eq[0]) or -180 < c7eq[0] < 0
    assert ds["basin_minimum_error_deg"].attrs["units"] == "degree"


@pytest.mark.slow
def test_sandcv_exploration_bars(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=sandcv_alanine", f"outputs_root={tmp_path}",
                  cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    ds = xr.open_dataset(next(tmp_path.glob("runs/*/*/results.nc")))
    assert float(ds["training_fraction_unsampled_basin"]) == 0.0
    assert float(ds["fraction_unsampled_basin"]) > 0.0
    assert np.all(ds["basin_minimum_error_deg"].values < 20.0)
