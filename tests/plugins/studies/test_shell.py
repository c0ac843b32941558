"""The shell study end to end from the command line, and its convergence post-processing."""

import numpy as np
import pytest
import xarray as xr

from pointatlas import open_run
from pointatlas_studies.shell_convergence import (convergence_figures,
                                                  convergence_table, last_rate)


def test_plate_run_writes_results_vtp_and_report(tmp_path, run_cli):
    out = tmp_path / "out"
    r = run_cli("pointatlas", "experiment=shell_plate", "source.n_points=196",
                "study.quadrature_order=4", f"outputs_root={out}", "quiet=true", cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    run_dir = next(out.glob("runs/*/*"))
    ds = open_run(run_dir)
    for v in list(ds.data_vars) + list(ds.coords):
        assert "long_name" in ds[v].attrs and "units" in ds[v].attrs, v
    assert int(ds["dof"]) == 3 * (int(ds["n_points"]) + int(ds["n_ghosts"]))
    assert ds["displacement"].attrs["reference"] == pytest.approx(1.2257045)
    assert float(ds["relative_error"]) < 0.01  # 0.2 % at this size (thesis value)
    assert list(ds["reference"].values)[0].startswith("thesis")
    from pointatlas_solvers.linear_backends import resolve_backend

    # the default solver 'auto' is PARDISO when pypardiso is installed, and the run says so
    assert ds.attrs["linear_solver"] == resolve_backend("auto")
    assert ds["displacement_field"].dims == ("point", "dim")
    _check_vtp(run_dir / "shell.vtp", ds)
    r = run_cli("pointatlas-report", str(run_dir), cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    html_text = (run_dir / "report.html").read_text()
    assert "Deformed surface" in html_text and html_text.index("Result") < html_text.index("Figures")
    # the report draws the surface: its triangles cover every sampled point
    assert np.unique(ds["surface_triangle"].values).size == int(ds["n_points"])


def _check_vtp(path, ds):
    """shell.vtp: the plate's triangles over every point, none degenerate, and the run's
    results with their units (what ParaView shows)."""
    import pyvista as pv

    mesh = pv.read(path)
    X = ds["position"].values
    np.testing.assert_array_equal(mesh.points, X)
    tri = np.asarray(mesh.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    assert len(tri) == mesh.n_cells == 2 * 13 ** 2        # 14 × 14 points on the quarter
    assert np.unique(tri).size == len(X)
    area = 0.5 * np.linalg.norm(np.cross(X[tri[:, 1]] - X[tri[:, 0]],
                                         X[tri[:, 2]] - X[tri[:, 0]]), axis=1)
    assert area.min() > 0 and area.sum() == pytest.approx(25.0, rel=1e-12)
    u = ds["displacement_field"].values
    np.testing.assert_array_equal(mesh.point_data["u"], u)
    np.testing.assert_allclose(mesh.point_data["u_magnitude"], np.linalg.norm(u, axis=1))
    mag = ds.attrs["magnification"]
    assert mesh.field_data["magnification"][0] == pytest.approx(mag)
    np.testing.assert_allclose(mesh.point_data["deformed"], X + mag * u)
    # the units of results.nc (the run's units_system: SI) and the quantity they came from
    attrs = ds["displacement_field"].attrs
    assert (attrs["units"], attrs["quantity"]) == ("m", "length")
    for name in ("u", "u_magnitude", "deformed"):
        assert mesh.field_data[f"{name}_units"][0] == "m"
        assert mesh.field_data[f"{name}_quantity"][0] == "length"
    assert mesh.field_data["on_boundary_units"][0] == "1"
    assert mesh.field_data["units_system"][0] == ds.attrs["units_system"] == "SI"


def _sweep(dofs, disps, refs=(1.0, 1.01)):
    n = len(dofs)
    return xr.Dataset(
        {"dof": (("n",), dofs), "displacement": (("n",), disps),
         "reference_value": (("n", "reference"), np.tile(refs, (n, 1))),
         "time_assembly": (("n",), np.linspace(1, 2, n)),
         "time_solve": (("n",), np.linspace(0.1, 0.2, n))},
        coords={"n": np.arange(n), "reference": ["a", "b"]})


def test_convergence_rate_and_monotonicity():
    dofs = np.array([4000.0, 1000.0, 2000.0, 8000.0])  # unsorted on purpose
    errs = 0.05 * (dofs / 1000.0) ** -1.0
    t = convergence_table(_sweep(dofs, 1.0 + errs))
    assert t["dof"].tolist() == [1000, 2000, 4000, 8000]
    assert t["rate"] == pytest.approx(-1.0, abs=1e-9)
    assert t["monotone"]
    np.testing.assert_allclose(t["errors"][:, 1], np.abs(1.0 + np.sort(errs)[::-1] - 1.01) / 1.01)
    bumpy = convergence_table(_sweep(dofs, 1.0 + np.array([0.01, 0.05, 0.02, 0.03])))
    assert not bumpy["monotone"]
    assert np.isnan(last_rate(np.array([1.0]), np.array([0.1])))
    titles = [t for t, _ in convergence_figures(_sweep(dofs, 1.0 + errs))]
    assert "rate over the last three refinements: -1.00" in titles[0]
    assert len(titles) == 3


def test_own_point_cloud_file_with_selectors_needs_no_code(tmp_path, run_cli):
    import pointatlas

    cloud = pointatlas.load_plugin("sources", "square_plate")(n_points=196, model="quarter") \
        .load(np.random.default_rng(0))
    np.savez(tmp_path / "plate.npz", points=cloud.points)
    supports = ("[{kind:clamped,where:{expression:'x > 4.99'}},"
                "{kind:clamped,where:{plane:[0,1,0,5.0]}},"
                "{kind:symmetry,normal:[1,0,0],where:{plane:[1,0,0,0]}},"
                "{kind:symmetry,normal:[0,1,0],where:{box:[-1,-0.01,-1,6,0.01,1]}}]")
    r = run_cli("pointatlas", "~experiment", "source=file", f"source.path={tmp_path}/plate.npz",
                "embedder=pca", "physics=kirchhoff_love", "study=shell",
                "study.quadrature_order=4", f"physics.supports={supports}",
                "physics.loads=[{kind:point,at:[0,0,0],force:[0,0,-50]}]",
                "study.references=[1.2257045]", f"outputs_root={tmp_path}/out", "quiet=true",
                cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    ds = open_run(next((tmp_path / "out").glob("runs/*/*")))
    assert float(ds["relative_error"]) < 0.01
