"""Abstract quantities become UDUNITS strings of the run's units system (CF conventions)."""
import numpy as np
import pytest
import xarray as xr
from cf_units import Unit

from pointatlas.units import UNIT_SYSTEMS, convert_units, parse_quantity, to_udunits

EXPRESSIONS = ["length", "energy / length^2", "energy/length²", "force / length^2",
               "mass / length", "length / time^2", "1 / time", "viscosity", "force*length"]


def test_parse_quantity():
    assert parse_quantity("energy / length^2") == {"energy": 1, "length": -2}
    assert parse_quantity("energy/length²") == {"energy": 1, "length": -2}
    assert parse_quantity("1 / time") == {"time": -1}
    assert parse_quantity("length / length") is None  # dimensionless: left as is
    for real in ("m", "kJ/mol", "degree", "rad/s", "1", "Pa s", "s-1"):
        assert parse_quantity(real) is None


@pytest.mark.parametrize("system", list(UNIT_SYSTEMS))
@pytest.mark.parametrize("expression", EXPRESSIONS)
def test_every_expression_is_a_udunits_string(system, expression):
    Unit(to_udunits(expression, system))  # raises if UDUNITS cannot parse it


def test_si_and_mm_values_are_the_same_physical_quantities():
    assert to_udunits("energy / length^2", "SI") == "J m-2"
    assert to_udunits("viscosity", "mm_N_s") == "MPa s"
    # the mm-N-s system is consistent: its energy is force times length, its mass F s²/L
    assert Unit(to_udunits("energy", "mm_N_s")).convert(1, Unit("N mm")) == pytest.approx(1)
    assert Unit(to_udunits("mass", "mm_N_s")).convert(1, Unit("N s2 mm-1")) == pytest.approx(1)
    assert Unit(to_udunits("viscosity", "mm_N_s")).convert(1, Unit("N s mm-2")) == pytest.approx(1)
    assert to_udunits("force / length^2", "nondimensional") == "1"
    with pytest.raises(ValueError, match="units_system 'imperial' is unknown"):
        to_udunits("length", "imperial")


def test_convert_units_keeps_the_quantity():
    ds = xr.Dataset({"u": ("point", np.zeros(3), {"long_name": "u", "units": "length"}),
                     "phi": ((), 0.0, {"long_name": "angle", "units": "degree"})})
    convert_units(ds, "mm_N_s")
    assert ds["u"].attrs == {"long_name": "u", "units": "mm", "quantity": "length"}
    assert ds["phi"].attrs["units"] == "degree" and "quantity" not in ds["phi"].attrs
    assert ds.attrs["units_system"] == "mm_N_s"


def test_a_run_in_mm_and_a_refused_system(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=shell_plate", "source.n_points=121",
                  "units_system=mm_N_s", f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-2000:]
    ds = xr.open_dataset(next(tmp_path.glob("runs/*/*/results.nc")))
    assert ds["displacement"].attrs["units"] == "mm" and ds.attrs["units_system"] == "mm_N_s"
    assert ds["strain_energy"].attrs["units"] == "mJ"
    out = run_cli("pointatlas", "units_system=imperial", f"outputs_root={tmp_path}",
                  cwd=tmp_path)
    assert out.returncode == 2 and "units_system" in out.stderr and "Traceback" not in out.stderr
