"""The five Stokes experiments of issue 19 from the command line, their contract variables
and bars; a user's stroke from a file; bad input refused in one line."""
import numpy as np
import pytest
import xarray as xr


def _run(run_cli, tmp_path, *args):
    out = run_cli("pointatlas", *args, f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    return xr.open_dataset(next(tmp_path.glob("runs/*/*/results.nc")))


def test_sphere_drag_experiment(run_cli, tmp_path):
    ds = _run(run_cli, tmp_path, "experiment=stokes_sphere_drag")
    assert int(ds["n_elements"]) <= 64
    assert float(ds["drag_reference"]) == pytest.approx(6 * np.pi)
    assert float(ds["drag"]) == pytest.approx(6 * np.pi, rel=1e-3)
    assert float(ds["relative_error"]) < 1e-3


def test_spheroid_drag_refinement_shows_third_order(run_cli, tmp_path):
    ds = _run(run_cli, tmp_path, "experiment=stokes_sphere_drag", "study.aspect_ratio=2",
              "study.refinement=[8,16,32,64]")
    err = ds["refinement_error"].values
    assert (np.diff(err) < 0).all() and err[-1] < 1e-6
    assert ds["refinement_rate"].values[-1] > 2.5


def test_sphere_rotation_experiment(run_cli, tmp_path):
    ds = _run(run_cli, tmp_path, "experiment=stokes_sphere_rotation")
    assert float(ds["torque_reference"]) == pytest.approx(8 * np.pi)
    assert float(ds["relative_error"]) < 1e-3
    assert float(ds["torque"]) == pytest.approx(8 * np.pi, rel=1e-3)


def test_squirmer_experiment(run_cli, tmp_path):
    ds = _run(run_cli, tmp_path, "experiment=squirmer")
    assert float(ds["swimming_speed_reference"]) == pytest.approx(2 / 3)
    assert float(ds["relative_error"]) < 1e-3
    assert float(ds["power"]) == pytest.approx(float(ds["power_reference"]), rel=1e-2)


def test_scallop_experiment(run_cli, tmp_path):
    ds = _run(run_cli, tmp_path, "experiment=scallop")
    half = abs(float(ds["half_stroke_displacement"]))
    assert half > 1e-3
    assert abs(float(ds["net_displacement"])) < 1e-6 * half
    assert abs(float(ds["net_rotation"])) < 1e-6 * abs(float(ds["half_stroke_rotation"]))


def test_small_amplitude_stroke_experiment(run_cli, tmp_path):
    ds = _run(run_cli, tmp_path, "experiment=small_amplitude_stroke")
    assert float(ds["amplitude_exponent"]) == pytest.approx(2.0, abs=0.1)
    assert float(ds["relative_error"]) < 0.05
    eps = ds["amplitude"].values
    assert eps.max() / eps.min() >= 10


def test_a_users_stroke_from_a_file(run_cli, tmp_path):
    from pointatlas_studies import meridian_motions as mm

    t, X, V = mm.small_amplitude_stroke(1.0, 65, 8, 0.1, {2: 1.0, 3: 1j}, {})
    np.savez(tmp_path / "stroke.npz", times=t, shapes=X, velocities=V)
    ds = _run(run_cli, tmp_path, "experiment=scallop", "study.case=stroke_file",
              f"study.stroke_file={tmp_path / 'stroke.npz'}", "physics.n_elements=24")
    assert ds.sizes["phase"] == 9
    for name in ("net_displacement", "net_rotation", "efficiency_out",
                 "efficiency_inner_outer", "mean_power_out"):
        assert np.isfinite(float(ds[name])), name
    assert float(ds["mean_power_inner_outer"]) > float(ds["mean_power_out"]) > 0


@pytest.mark.parametrize("args, message", [
    (("physics.viscosity=-1",), "physics.viscosity=-1"),
    (("study.case=stroke_file", "study.stroke_file=/nonexistent.npz"), "no such file"),
    (("study.case=stroke_file", "study.stroke_file=STROKE"), "not periodic"),
])
def test_bad_input_one_line_no_results(run_cli, tmp_path, args, message):
    from pointatlas_studies import meridian_motions as mm

    t, X, V = mm.small_amplitude_stroke(1.0, 33, 6, 0.1, {2: 1.0, 3: 1j}, {})
    X[-1, 3:-3] *= 1.05
    np.savez(tmp_path / "open.npz", times=t, shapes=X, velocities=V)
    args = [a.replace("STROKE", str(tmp_path / "open.npz")) for a in args]
    out = run_cli("pointatlas", "experiment=scallop", *args, f"outputs_root={tmp_path}",
                  cwd=tmp_path)
    assert out.returncode != 0
    assert "Traceback" not in out.stderr
    assert message in out.stderr, out.stderr[-2000:]
    assert not list(tmp_path.glob("runs/*/*/results.nc"))
