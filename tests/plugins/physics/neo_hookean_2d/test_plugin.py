"""The physics plugin: its contract, its Config rules, its Dataset and its refusals."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas.testing import check_physics

SMALL = {"n_triangles": 120, "n_steps": 400, "save_every": 100}


def _cls():
    return pointatlas.load_plugin("physics", "neo_hookean_2d")


class _Ctx:
    log = None


def test_contract():
    check_physics(_cls())


@pytest.fixture(scope="module")
def swing():
    return _cls()(**SMALL, initial_load=[2.0, -1.0], initial_velocity_gradient=[0, 1.0, 0, 0]
                  ).solve(_Ctx())


def test_dataset_dims_units_and_energies(swing):
    ds = swing
    assert ds["position"].dims == ("time", "node", "dim")
    assert list(ds["dim"].values) == ["x", "y"]
    assert ds.sizes["time"] == 5 and list(ds["step"].values) == [0, 100, 200, 300, 400]
    assert np.allclose(ds["time"], ds["step"] * float(ds["dt"]))
    for name, var in ds.variables.items():
        assert var.attrs.get("long_name") and var.attrs.get("units"), name
    assert ds["face_node_connectivity"].dims == ("face", "corner")
    assert ds["mesh_topology"].attrs["cf_role"] == "mesh_topology"
    X = np.column_stack([ds["node_x"], ds["node_y"]])
    assert np.allclose(ds["displacement"], ds["position"] - X[None])
    total = ds["kinetic_energy"] + ds["elastic_energy"] + ds["gravity_energy"]
    assert np.allclose(ds["total_energy"], total)
    assert np.allclose(ds["potential_energy"], ds["elastic_energy"] + ds["gravity_energy"])
    assert float(ds["energy_error"]) < 1e-3
    assert float(ds["critical_time_step"]) > float(ds["dt"])
    clamped = ds["clamped"].values.astype(bool)
    assert np.allclose(ds["velocity"].values[:, clamped], 0)
    # released from a sideways static state with a sway velocity v_x = y
    assert ds["displacement"].sel(dim="x").isel(time=0).max() > 0.01
    assert float(ds["velocity"].sel(dim="x").isel(time=0).max()) == pytest.approx(1.5)


def test_the_dataset_round_trips_through_netcdf(swing, tmp_path):
    import xarray as xr

    from pointatlas.results import write_results

    path = write_results(swing, tmp_path / "results.nc")
    with xr.open_dataset(path) as back:
        assert np.allclose(back["position"], swing["position"])
        assert back["face_node_connectivity"].attrs["start_index"] == 0


def test_given_initial_state_and_steps():
    p = _cls()(**SMALL, gravity=[0.0, 0.0])
    body = p.build_body()
    x0 = body.reference.copy()
    v0 = np.zeros_like(x0)
    ds = p.solve(_Ctx(), x0=x0, v0=v0, n_steps=30)
    assert list(ds["step"].values) == [0, 30]
    assert np.allclose(ds["position"], x0) and float(abs(ds["total_energy"]).max()) < 1e-20
    with pytest.raises(InputError, match=r"x0 must be a finite array of shape \(\d+, 2\)"):
        p.solve(_Ctx(), x0=x0[:-1])


def test_consistent_mass_and_a_box_clamp():
    ds = _cls()(**SMALL, mass="consistent", clamp={"box": [-1, -1, 1, 0.05]}).solve(_Ctx())
    assert ds["clamped"].sum() > ds.sizes["node"] // 40
    assert "consistent" in ds.attrs["title"]


def test_a_mesh_file_is_used(tmp_path):
    meshio = pytest.importorskip("meshio")
    from pointatlas_physics.neo_hookean_2d.mesh import tapered_column

    m = tapered_column(height=1.0, base_width=0.3, top_width=0.3, n_triangles=80)
    meshio.write(tmp_path / "block.vtu", meshio.Mesh(m.nodes, [("triangle", m.triangles)]))
    ds = _cls()(mesh_file=str(tmp_path / "block.vtu"), n_steps=10, save_every=10).solve(_Ctx())
    assert ds.sizes["face"] == m.n_triangles


def test_a_non_positive_bulk_modulus_is_refused():
    with pytest.raises(ConfigError, match=r"physics.lam \+ physics.mu = -100 must be > 0"):
        _cls()(lam=-600.0, mu=500.0).solve(_Ctx())
    with pytest.raises(ConfigError, match=r"physics.mu=0.0 is invalid: it must be a number > 0"):
        _cls()(mu=0.0).solve(_Ctx())


def test_a_time_step_above_the_limit_is_refused():
    with pytest.raises(InputError, match=r"physics.dt=0.01 is above the stability limit"):
        _cls()(**{**SMALL, "n_triangles": 60}, dt=1e-2).solve(_Ctx())


def test_bad_clamps_and_files_are_refused(tmp_path):
    with pytest.raises(InputError, match="selects 0 node"):
        _cls()(**SMALL, clamp={"y_below": -0.5}).solve(_Ctx())
    with pytest.raises(ConfigError, match="physics.clamp='top' is not a selector"):
        _cls()(**SMALL, clamp="top").solve(_Ctx())
    (tmp_path / "x.msh").write_text("$MeshFormat\nbroken")
    with pytest.raises(InputError, match=r"physics.mesh_file=.*x.msh' cannot be read"):
        _cls()(mesh_file=str(tmp_path / "x.msh")).solve(_Ctx())
