"""rom_pendulum from the command line (the whole experiment: 10⁴ periods in seconds)."""
import pytest
import xarray as xr


def test_rom_pendulum_meets_its_bars(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=rom_pendulum", f"outputs_root={tmp_path}",
                  cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    ds = xr.open_dataset(next(tmp_path.glob("runs/*/*/results.nc")))
    assert float(ds["relative_error"]) < 5e-3
    assert float(ds["period"]) == pytest.approx(float(ds["period_reference"]), rel=5e-3)
    assert int(ds["n_periods"]) == 10000
    assert abs(float(ds["energy_drift"])) < 1e-3
    assert float(ds["energy_error_last"]) < 0.05


def test_an_amplitude_outside_the_sampled_arc_is_refused(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=rom_pendulum", "study.amplitude=130",
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode != 0 and "Traceback" not in out.stderr
    assert "outside the sampled arc" in out.stderr
