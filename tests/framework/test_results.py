"""netCDF results: attrs round-trip, atomic writing, schema guard."""
import json

import numpy as np
import pytest
import xarray as xr

import pointatlas
from pointatlas.errors import InputError, SchemaError
from pointatlas.results import check_variables, metric_values, write_results

ATTRS = {
    "Conventions": "CF-1.10", "title": "t", "source": "pointatlas 0.1.0", "history": "now: cmd",
    "config": "seed: 0\n", "overrides": ["a=1", "b=x"], "git_commit": "", "seed": 3,
    "hostname": "h", "wall_time_s": 1.5, "status": "completed", "plugins": {"study": "s"},
    "flag": True, "nothing": None,
}


def small_dataset():
    return xr.Dataset(
        {"x": (("point",), np.arange(3.0), {"long_name": "x", "units": "m"}),
         "area": ((), 12.5, {"long_name": "area", "units": "m2", "reference": 12.566})},
        coords={"point": ("point", np.arange(3), {"long_name": "point index", "units": "1"})},
    )


def test_round_trip_keeps_attrs(tmp_path):
    path = write_results(small_dataset(), tmp_path, ATTRS)
    ds = pointatlas.open_run(tmp_path)
    assert path.name == "results.nc"
    assert json.loads(ds.attrs["overrides"]) == ["a=1", "b=x"]
    assert json.loads(ds.attrs["plugins"]) == {"study": "s"}
    assert ds.attrs["seed"] == 3 and ds.attrs["wall_time_s"] == 1.5
    assert ds.attrs["flag"] == 1 and ds.attrs["nothing"] == ""
    assert ds.attrs["pointatlas_schema"] == 1
    assert ds["area"].attrs["units"] == "m2"
    assert metric_values(ds) == {"area": 12.5}
    assert not list(tmp_path.glob(".results.nc.*"))


def test_failed_write_leaves_no_file(tmp_path, monkeypatch):
    def boom(self, path, **kw):
        open(path, "wb").write(b"partial")
        raise RuntimeError("disk full")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", boom)
    with pytest.raises(RuntimeError):
        write_results(small_dataset(), tmp_path, ATTRS)
    assert list(tmp_path.iterdir()) == []


def test_newer_schema_is_refused(tmp_path):
    ds = small_dataset()
    ds.attrs["pointatlas_schema"] = 99
    ds.to_netcdf(tmp_path / "results.nc")
    with pytest.raises(SchemaError, match="newer.*Upgrade"):
        pointatlas.open_run(tmp_path)


def test_missing_results_is_a_clear_error(tmp_path):
    with pytest.raises(InputError, match="no results file"):
        pointatlas.open_run(tmp_path)


def test_variables_must_have_units():
    ds = small_dataset()
    ds["bad"] = ((), 1.0)
    with pytest.raises(ValueError, match="bad"):
        check_variables(ds)
