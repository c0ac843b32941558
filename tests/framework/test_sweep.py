"""open_sweep: grids become dimensions, other sweeps a `run` dim."""
import numpy as np

import pointatlas
from pointatlas.results import write_results


def fake_run(path, overrides, value):
    ds = __import__("xarray").Dataset({"err": ((), value, {"long_name": "error", "units": "1"})})
    write_results(ds, path / "results.nc", {"overrides": overrides, "status": "completed"})


def test_grid_sweep_has_parameter_dims(tmp_path):
    k = 0
    for n in (100, 200):
        for e in ("pca", "isomap"):
            fake_run(tmp_path / str(k), [f"source.n_points={n}", f"embedder={e}"], n * (1 + (e == "pca")))
            k += 1
    ds = pointatlas.open_sweep(tmp_path)
    assert set(ds["err"].dims) == {"source_n_points", "embedder"}
    assert ds["source_n_points"].attrs["override"] == "source.n_points"
    assert float(ds["err"].sel({"source_n_points": 200, "embedder": "pca"})) == 400
    assert ds["err"].dtype.kind == "i"  # integers in every run, no padding: still integers
    assert [r["overrides"] for r in __import__("json").loads(ds.attrs["run_attrs"])][0] == \
        '["source.n_points=100", "embedder=pca"]' 


def test_single_parameter_sweep(tmp_path):
    for k, n in enumerate((10, 20, 30)):
        fake_run(tmp_path / str(k), [f"source.n_points={n}"], 1.0 / n)
    ds = pointatlas.open_sweep(tmp_path)
    assert ds["err"].dims == ("source_n_points",)
    np.testing.assert_allclose(ds["err"].values, [0.1, 0.05, 1 / 30])


def test_non_grid_sweep_uses_run_dim(tmp_path):
    for k, ov in enumerate([["a=1", "b=1"], ["a=2", "b=1"], ["a=1", "b=2"]]):
        fake_run(tmp_path / str(k), ov, float(k))
    ds = pointatlas.open_sweep(tmp_path)
    assert ds["err"].dims == ("run",)
    assert list(ds["a"].values) == [1, 2, 1]


def test_runs_of_different_mesh_sizes_are_padded(tmp_path):
    xr = __import__("xarray")
    for k, n in enumerate((2, 3)):
        ds = xr.Dataset({"err": ((), float(n), {"long_name": "error", "units": "1"}),
                         "tri": (("triangle", "corner"), np.arange(3 * n).reshape(n, 3),
                                 {"long_name": "triangles", "units": "1"})})
        write_results(ds, tmp_path / str(k) / "results.nc",
                      {"overrides": [f"source.n_points={n}"], "status": "completed"})
    ds = pointatlas.open_sweep(tmp_path)
    assert ds["tri"].shape == (2, 3, 3) and np.isnan(ds["tri"].values[0, 2]).all()
    assert ds["err"].dtype.kind == "f" and list(ds["err"].values) == [2.0, 3.0]
