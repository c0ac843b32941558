"""The nonlinear shell study from the command line: increments, monitors, resume."""
import numpy as np
import pytest
import xarray as xr

from pointatlas import open_run

ARGS = ["experiment=shell_open_hemisphere", "source.n_points=200", "study.n_increments=2",
        "study.max_load_factor=0.1", "study.quadrature_order=4", "quiet=true"]


def test_open_hemisphere_path_and_resume(tmp_path, run_cli, paraview_series):
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
    series = paraview_series(run_dir / "shell_nonlinear.pvd")
    _check_snapshots(series, ds)
    # resuming the finished path gives its results again, every increment included
    r = run_cli("pointatlas", *ARGS, f"study.resume_from={run_dir}",
                f"outputs_root={tmp_path / 'out2'}", cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    resumed = open_run(next((tmp_path / "out2").glob("runs/*/*")))
    assert resumed["load_factor"].values.tolist() == pytest.approx([0.05, 0.1])
    assert resumed["radial_displacement"].values == pytest.approx(
        ds["radial_displacement"].values, abs=1e-12)
    # ... and its ParaView series: the same collection, the same arrays
    resumed_dir = next((tmp_path / "out2").glob("runs/*/*"))
    assert (resumed_dir / "shell_nonlinear.pvd").read_text() == \
        (run_dir / "shell_nonlinear.pvd").read_text()
    for (t, a), (s, b) in zip(paraview_series(resumed_dir / "shell_nonlinear.pvd"), series):
        assert t == s and set(a.array_names) == set(b.array_names)
        for name in ("u", "energy_density", "bending_fraction"):
            np.testing.assert_allclose(a.point_data[name], b.point_data[name], rtol=0,
                                       atol=1e-12 * np.abs(b.point_data[name]).max())
    # a resume with another path is refused, naming the setting (one line, no traceback)
    r = run_cli("pointatlas", *ARGS[:-2], "study.max_load_factor=0.15", "study.n_increments=3",
                f"study.resume_from={run_dir}", f"outputs_root={tmp_path / 'out3'}",
                "quiet=true", cwd=tmp_path)
    assert r.returncode != 0 and "Traceback" not in r.stderr
    assert "study.max_load_factor = 0.1" in r.stderr and "study.max_load_factor = 0.15" in r.stderr


def _check_snapshots(series, ds):
    """One .vtp per increment at timestep λ holding the Dataset's fields with its units."""
    assert [t for t, _ in series] == ds["load_factor"].values.tolist() == \
        pytest.approx([0.05, 0.1])
    for k, (_, mesh) in enumerate(series):
        np.testing.assert_array_equal(mesh.points, ds["position"].values)
        u = ds["displacement_field"].values[k]
        np.testing.assert_array_equal(mesh.point_data["u"], u)
        np.testing.assert_allclose(mesh.point_data["u_magnitude"], np.linalg.norm(u, axis=1))
        for name in ("energy_density", "bending_fraction"):
            np.testing.assert_array_equal(mesh.point_data[name], ds[name].values[k])
            assert mesh.field_data[f"{name}_units"][0] == ds[name].attrs["units"]
        assert mesh.field_data["u_units"][0] == ds["displacement_field"].attrs["units"] == "m"
        assert mesh.field_data["energy_density_units"][0] == "J m-2"
        assert mesh.field_data["load_factor"][0] == ds["load_factor"].values[k]
        assert mesh.field_data["load"][0] == pytest.approx(ds["load"].values[k])
        assert mesh.field_data["load_units"][0] == "N"


@pytest.mark.slow
def test_nonlinear_run_on_a_vtp_point_cloud_needs_no_code(tmp_path, run_cli):
    """The open hemisphere's points as a .vtp file, supports, loads and monitors given only
    on the command line: the same path as the built-in experiment (Sze et al. at 0.1 P_max).
    A study (``-m slow``, a minute of CI): the default suite runs a user's point file with
    selectors through the linear shell (test_shell::test_own_point_cloud_file_with_selectors_
    needs_no_code) and the nonlinear path from the command line (above)."""
    import numpy as np
    import pyvista as pv

    import pointatlas

    cloud = pointatlas.load_plugin("sources", "hemisphere")(
        n_points=200, model="quarter", hole_angle_deg=18.0).load(np.random.default_rng(0))
    pv.PolyData(cloud.points).save(str(tmp_path / "shell.vtp"))
    supports = ("[{kind:symmetry,normal:[1,0,0],where:{plane:[1,0,0,0]}},"
                "{kind:symmetry,normal:[0,1,0],where:{plane:[0,1,0,0]}},"
                "{kind:fixed,components:[2],where:{expression:'z > 9.4 and abs(y) < 1e-6'}}]")
    loads = "[{kind:point,at:[10,0,0],force:[200,0,0]},{kind:point,at:[0,10,0],force:[0,-200,0]}]"
    r = run_cli("pointatlas", "~experiment", "source=file", f"source.path={tmp_path}/shell.vtp",
                "embedder=pca", "physics=kirchhoff_love", "study=shell_nonlinear",
                "physics.young_modulus=6.825e7", "physics.thickness=0.04",
                f"physics.supports={supports}", f"physics.loads={loads}",
                "study.quadrature_order=4", "study.n_increments=2", "study.max_load_factor=0.1",
                "study.full_load=400", "study.monitor_points=[10,0,0,0,10,0]",
                "study.monitor_directions=[1,0,0,0,-1,0]", "study.monitor_names=[A,B]",
                "study.monitor_magnitude=true", f"outputs_root={tmp_path}/out", "quiet=true",
                cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    ds = open_run(next((tmp_path / "out").glob("runs/*/*")))
    a, b = ds["displacement_at"].values[-1]
    # 200 points without the source's markers (the built-in run gives 1.40 / 1.68)
    assert a == pytest.approx(1.499, rel=0.15) and b == pytest.approx(1.840, rel=0.15)
    assert ds["energy_density"].dims == ("increment", "sample")
    assert float(ds["energy_density"].min()) >= 0 and float(ds["energy_density"].max()) > 0


def test_branch_switching_needs_arc_length():
    from types import SimpleNamespace

    import numpy as np

    from pointatlas.errors import ConfigError
    from pointatlas_studies.shell_nonlinear import ShellNonlinearStudy

    s = SimpleNamespace(imposed=[], has_loads=True)   # what path_problem reports
    study = ShellNonlinearStudy(control="force", branch_switching=True)
    with pytest.raises(ConfigError, match="branch_switching=true needs study.control=arc_length"):
        study._check_control(s)
    ShellNonlinearStudy(control="arc_length", branch_switching=True)._check_control(s)
    # and the quasi-static snaps of stable_path are for force or displacement control
    with pytest.raises(ConfigError, match="stable_path=true needs study.control=force or disp"):
        ShellNonlinearStudy(control="arc_length", stable_path=True)._check_control(s)
    ShellNonlinearStudy(control="force", stable_path=True)._check_control(s)
