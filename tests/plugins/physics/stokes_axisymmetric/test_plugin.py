"""The physics plugin: its contract, its Config rules and its Dataset."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas.testing import check_physics


def _cls():
    return pointatlas.load_plugin("physics", "stokes_axisymmetric")


class _Ctx:
    log = None


def test_contract():
    check_physics(_cls())


def test_a_non_positive_viscosity_is_refused():
    with pytest.raises(ConfigError, match=r"physics.viscosity=0.0 is invalid: it must be a "
                                          r"number > 0"):
        _cls()(viscosity=0.0).solve(_Ctx(), shapes=np.zeros((5, 2)), velocities=np.zeros((5, 3)))


def test_dataset_names_units_and_values():
    th = np.linspace(0, np.pi, 65)
    nodes = np.column_stack([np.sin(th), np.cos(th)])
    v = np.zeros((65, 3))
    v[:, 1] = 1.0
    ds = _cls()(n_elements=32).solve(_Ctx(), shapes=nodes, velocities=v, motion="prescribed")
    assert float(ds["axial_force"][0]) == pytest.approx(6 * np.pi, rel=1e-8)
    assert ds["traction"].dims == ("phase", "element", "component")
    assert "arclength" in ds.coords and ds["arclength"].values[0, -1] < np.pi
    for name, var in ds.variables.items():
        assert "units" in var.attrs and "long_name" in var.attrs, name


def test_permeation_none_refuses_a_volume_change():
    th = np.linspace(0, np.pi, 65)
    nodes = np.column_stack([np.sin(th), np.cos(th)])
    v = np.zeros((65, 3))
    v[:, :2] = 0.1 * nodes
    with pytest.raises(InputError, match="physics.permeation=uniform"):
        _cls()(n_elements=16, permeation="none").solve(_Ctx(), shapes=nodes, velocities=v)
