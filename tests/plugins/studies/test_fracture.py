"""study=fracture on a small centre-cracked plate: the crack grows, υ never increases at
any point from one increment to the next (exactly), the energies are consistent, and a run
interrupted after two increments and resumed gives the uninterrupted results."""
import numpy as np
import pytest
import xarray as xr

# the plate: CENTRE_CRACKED_PLATE in conftest.py (run by the run_plate fixture)


def test_a_path_grows_the_crack_irreversibly_and_resumes_exactly(tmp_path, run_plate,
                                                                  interrupt_fracture,
                                                                  paraview_series):
    """One test, so that the path is computed once per worker: the checks below, then the
    same path killed after two increments and resumed."""
    full = run_plate(tmp_path / "full")
    series = paraview_series(tmp_path / "full" / "fracture.pvd")
    _check_snapshots(series, full)
    _check_growth(full)
    _check_energies(full)
    _check_resume(tmp_path, run_plate, interrupt_fracture, full)
    # the resumed run's ParaView series is the uninterrupted one's
    assert (tmp_path / "b" / "fracture.pvd").read_text() == \
        (tmp_path / "full" / "fracture.pvd").read_text()
    for (_, a), (_, b) in zip(paraview_series(tmp_path / "b" / "fracture.pvd"), series):
        for name in ("phase_field", "u", "deformed"):
            np.testing.assert_array_equal(a.point_data[name], b.point_data[name])


def _check_snapshots(series, full):
    """fracture.pvd: the six increments at timestep t, each .vtp with υ and u of the
    results (the plate's 441 points, 2 · 20² triangles) and their units."""
    assert [t for t, _ in series] == full["load_factor"].values.tolist()
    assert series[0][0] == 0.0 and series[-1][0] == pytest.approx(0.55)
    for k, (t, mesh) in enumerate(series):
        assert mesh.n_cells == 2 * 20 ** 2
        np.testing.assert_array_equal(mesh.points, full["position"].values)
        np.testing.assert_array_equal(mesh.point_data["phase_field"], full["phase_field"][k])
        np.testing.assert_array_equal(mesh.point_data["u"], full["displacement"][k])
        assert mesh.field_data["TimeValue"][0] == t == mesh.field_data["load_factor"][0]
        # the run's SI units (results.nc's; this in-process Dataset keeps the quantity)
        assert mesh.field_data["u_quantity"][0] == full["displacement"].attrs["units"]
        assert mesh.field_data["u_units"][0] == "m"
        assert mesh.field_data["phase_field_units"][0] == "1"


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


def _check_resume(tmp_path, run_plate, interrupt, full):
    interrupt(lambda: run_plate(tmp_path / "a"), after=3)
    with xr.open_dataset(tmp_path / "a" / "increments.nc") as saved:
        assert saved.sizes["increment"] == 3
    resumed = run_plate(tmp_path / "b", f"study.resume_from={tmp_path / 'a'}")
    assert resumed.sizes == full.sizes
    for name, var in full.variables.items():
        if var.dtype.kind in "biuf":
            np.testing.assert_array_equal(resumed[name].values, var.values, err_msg=name)


def test_a_resume_with_other_settings_is_refused(tmp_path, run_plate, interrupt_fracture):
    from pointatlas.errors import ConfigError

    interrupt_fracture(lambda: run_plate(tmp_path / "a"))
    with pytest.raises(ConfigError, match="physics.fracture_toughness"):
        run_plate(tmp_path / "b", f"study.resume_from={tmp_path / 'a'}",
             "physics.fracture_toughness=2e-3")


def test_a_staggered_solve_that_does_not_converge_stops_the_path_flagged(tmp_path, run_plate):
    """Past the smallest step the path stops: the converged increments are the results and
    the run says it did not finish (warnings, stopped), never a non-converged state."""
    ds = run_plate(tmp_path / "run", "physics.max_staggered=4", "study.n_increments=2",
              "study.min_step_fraction=0.25")
    assert "staggered solve did not converge" in ds.attrs["warnings"]
    assert ds.attrs["stopped"].startswith("the staggered solve did not converge")
    t = ds["load_factor"].values
    assert 0 < t[-1] < 0.55 and np.all(ds["staggered_iterations"].values[1:] <= 4)


def test_a_traction_free_crack_breaks_with_the_phase_field_kept_in_range(tmp_path):
    """fracture_griffith's traction-free crack on 121 points (κ̄ = 2 spacings) pulled until
    the ligament is broken: υ stays in [0, 1] at every point (the LME stiffness has no
    maximum principle; without the bound V ≥ 0 the band next to the broken ligament
    overshoots to min υ = −0.029 here, measured), and the crack does break the plate."""
    from pointatlas.testing import composed_context

    ctx = composed_context(tmp_path, [
        "experiment=fracture_griffith", "source.n_points=121", "physics.length_scale=0.1",
        "study.n_increments=4", "study.max_factor=0.8", "study.griffith_half_length=null",
        "study.min_step_fraction=1.0"])
    ds = ctx.plugin("study").run(ctx)
    v = ds["phase_field"].values
    assert v.min() >= 0.0 and v.max() <= 1.0 + 1e-12        # Σ p_a = 1 to round-off
    assert v[-1].min() < 0.05                                   # broken, not vacuous
    r = ds["reaction"].values
    assert r[-1] < 0.1 * r.max()
