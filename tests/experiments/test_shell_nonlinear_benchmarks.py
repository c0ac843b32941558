"""The nonlinear shell experiments as shipped meet the issue's bars against Sze, Liu & Lo 2004
(BENCHMARKS.md). Each runs its full default load path (hemisphere ~3 min, pull-out ~25 min on
2 cores), so both are ``slow``: ``pytest -m slow tests/experiments``."""
import pytest

import pointatlas


def _run(run_cli, tmp_path, experiment):
    proc = run_cli("pointatlas", f"experiment={experiment}", f"hydra.run.dir={tmp_path}/run",
                   "quiet=true", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return pointatlas.open_run(tmp_path / "run")


@pytest.mark.slow
def test_open_hemisphere_within_three_percent_at_every_level(tmp_path, run_cli):
    ds = _run(run_cli, tmp_path, "shell_open_hemisphere")
    assert ds.attrs["stopped"] == "completed the load path"
    assert float(ds["relative_error_curve"].max()) < 0.03     # measured 0.92 %
    assert int(ds["stable"].min()) == 1


@pytest.mark.slow
def test_pullout_within_three_percent_before_and_five_after_the_snap(tmp_path, run_cli):
    ds = _run(run_cli, tmp_path, "shell_pullout")
    assert ds.attrs["stopped"] == "completed the load path"
    err = ds["relative_error_curve"]
    before = err.sel(reference_level=slice(None, 0.5))
    after = err.sel(reference_level=slice(0.525, None))
    assert float(before.max()) < 0.03                         # measured 0.63 %
    assert float(after.max()) < 0.05                          # measured 1.04 %
    # the steep rise of −u_B between 0.5 and 0.525 (table: 3.653 → 4.061) is crossed
    assert float(ds["load_factor"].max()) == pytest.approx(1.0)
    assert int(ds["stable"].min()) == 0 and int(ds["stable"][-1]) == 1
