"""study=fracture on a small centre-cracked plate: the crack grows, υ never increases at
any point from one increment to the next (exactly), the energies are consistent, and a run
interrupted after two increments and resumed gives the uninterrupted results."""
import numpy as np
import pytest
import xarray as xr

import pointatlas_studies.fracture_increments as store
from pointatlas.testing import composed_context

# A full plate [-0.5, 0.5]², 21 × 21 points (spacing 0.05), κ̄ = 0.1 (2 spacings), a crack
# of 2a = 0.4 across the centre, the bottom edge held, the top pulled to 0.055 in five steps:
# the crack grows stably from 0.033 on (the reaction peaks at 0.044) and the last step takes
# ~60 staggered iterations; about 35 s a run
SMALL = ["experiment=fracture_griffith", "source.model=full", "source.n_points=441",
         "physics.length_scale=0.1",
         "physics.precracks=[{polyline: [[-0.2, 0, 0], [0.2, 0, 0]]}]",
         "physics.supports=[{kind: fixed, components: [1, 2], where: {plane: [0, 1, 0, -0.5]}},"
         " {kind: displacement, value: [0, 0.1, 0], where: {plane: [0, 1, 0, 0.5]}}]",
         "study.n_increments=5", "study.max_factor=0.55", "study.jump_fraction=0.5",
         "study.griffith_half_length=null"]


class Killed(BaseException):
    """What a kill -9 leaves: the process stops right after a write, nothing else runs."""


def _run(run_dir, *overrides):
    ctx = composed_context(run_dir, [*SMALL, *overrides])
    return ctx.plugin("study").run(ctx)


def test_a_path_grows_the_crack_irreversibly_and_resumes_exactly(tmp_path, monkeypatch):
    """One test, so that the path is computed once per worker: the checks below, then the
    same path killed after two increments and resumed."""
    full = _run(tmp_path / "full")
    import pyvista as pv

    last = pv.read(tmp_path / "full" / "snapshots" / "increment_0005.vtp")
    np.testing.assert_array_equal(last.point_data["phase_field"], full["phase_field"][-1])
    _check_growth(full)
    _check_energies(full)
    _check_resume(tmp_path, monkeypatch, full)


def _check_growth(full):
    v = full["phase_field"].values               # (increment, point)
    assert v.shape[0] == 6
    assert np.all(np.diff(v, axis=0) <= 0.0)     # exactly: no point heals, ever
    # not vacuous: the band grows from the pre-crack's tips (|x| ≤ 0.2) along y = 0
    # (measured: fracture energy 6.37e-5 -> 8.47e-5; min υ at 0.3 ≤ |x| < 0.35 0.60 -> 0.22)
    E = full["fracture_energy"].values
    assert E[-1] > 1.25 * E[0]
    x = full["position"].values
    ahead = (np.abs(x[:, 0]) >= 0.3) & (np.abs(x[:, 0]) < 0.35) & (np.abs(x[:, 1]) < 0.03)
    assert v[0, ahead].min() > 0.5 and v[-1, ahead].min() < 0.3


def _check_energies(full):
    r, d = full["reaction"].values, full["imposed_displacement"].values
    assert r[0] == 0 and d[0] == 0 and np.all(np.diff(d) > 0)
    # Clapeyron at each converged increment (linear elasticity at the frozen phase field):
    # ½ r d = the elastic energy (measured within 1e-3); the reaction peaks, then softens
    np.testing.assert_allclose(0.5 * r[1:] * d[1:], full["elastic_energy"].values[1:],
                               rtol=1e-2)
    assert np.argmax(r) in (3, 4) and r[-1] < r.max()
    # energy balance of the quasi-static path (AT2 dissipates only into the crack): the work
    # of the reaction equals the change of elastic + fracture energy, up to the trapezoidal
    # rule's error on the softening curve in five steps (measured 2.3 % short at the end)
    stored = full["elastic_energy"].values + full["fracture_energy"].values
    change = stored - stored[0]
    work = full["external_work"].values
    assert np.all(np.diff(work) > 0)
    np.testing.assert_allclose(work[1:], change[1:], rtol=0.05)
    assert np.all(full["staggered_iterations"].values[1:] >= 1)


def _check_resume(tmp_path, monkeypatch, full):
    real = store.write

    def write_then_die(path, problem, records, step, settings):
        real(path, problem, records, step, settings)
        if len(records) == 3:
            raise Killed

    monkeypatch.setattr(store, "write", write_then_die)
    with pytest.raises(Killed):
        _run(tmp_path / "a")
    monkeypatch.setattr(store, "write", real)
    with xr.open_dataset(tmp_path / "a" / "increments.nc") as saved:
        assert saved.sizes["increment"] == 3
    resumed = _run(tmp_path / "b", f"study.resume_from={tmp_path / 'a'}")
    assert resumed.sizes == full.sizes
    for name, var in full.variables.items():
        if var.dtype.kind in "biuf":
            np.testing.assert_array_equal(resumed[name].values, var.values, err_msg=name)


def test_a_resume_with_other_settings_is_refused(tmp_path, monkeypatch):
    from pointatlas.errors import ConfigError

    real = store.write

    def write_then_die(path, problem, records, step, settings):
        real(path, problem, records, step, settings)
        raise Killed

    monkeypatch.setattr(store, "write", write_then_die)
    with pytest.raises(Killed):
        _run(tmp_path / "a")
    monkeypatch.setattr(store, "write", real)
    with pytest.raises(ConfigError, match="physics.fracture_toughness"):
        _run(tmp_path / "b", f"study.resume_from={tmp_path / 'a'}",
             "physics.fracture_toughness=2e-3")


def test_a_staggered_solve_that_does_not_converge_stops_the_path_flagged(tmp_path):
    """Past the smallest step the path stops: the converged increments are the results and
    the run says it did not finish (warnings, stopped), never a non-converged state."""
    ds = _run(tmp_path / "run", "physics.max_staggered=4", "study.n_increments=2",
              "study.min_step_fraction=0.25")
    assert "staggered solve did not converge" in ds.attrs["warnings"]
    assert ds.attrs["stopped"].startswith("the staggered solve did not converge")
    t = ds["load_factor"].values
    assert 0 < t[-1] < 0.55 and np.all(ds["staggered_iterations"].values[1:] <= 4)
