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


def big_run(path, n, e, seed):
    """A run with a chunked field (2^18 points: two 1 MiB chunks) and an integer count."""
    xr = __import__("xarray")
    rng = np.random.default_rng(seed)
    ds = xr.Dataset({"u": (("point",), rng.standard_normal(2**18), {"long_name": "u", "units": "m"}),
                     "count": ((), np.int64(n + seed), {"long_name": "count", "units": "1"})})
    write_results(ds, path / "results.nc",
                  {"overrides": [f"source.n_points={n}", f"embedder={e}"], "status": "completed"})


def grid_of_big_runs(tmp_path):
    k = 0
    for n in (100, 200):
        for e in ("pca", "isomap"):
            big_run(tmp_path / str(k), n, e, k)
            k += 1


def test_lazy_sweep_reads_nothing_until_computed_and_equals_the_eager_one(tmp_path):
    grid_of_big_runs(tmp_path)
    eager = pointatlas.open_sweep(tmp_path)
    with pointatlas.open_sweep(tmp_path, lazy=True) as lazy:
        u = lazy["u"]
        assert hasattr(u.data, "dask") and u.data.chunksize[u.dims.index("point")] < 2**18
        assert u.dims == eager["u"].dims and lazy["count"].dtype.kind == "i"
        # a reduction chunk by chunk (sums regrouped: equal to round-off), then every value
        np.testing.assert_allclose(u.mean("point").values, eager["u"].mean("point").values,
                                   rtol=1e-12, atol=1e-15)
        np.testing.assert_array_equal(u.values, eager["u"].values)
        np.testing.assert_array_equal(lazy["count"].values, eager["count"].values)
        assert int(lazy["count"].sel(source_n_points=200, embedder="isomap")) == 203


def test_lazy_sweep_from_sweep_nc(tmp_path):
    from pointatlas.sweep import write_sweep

    grid_of_big_runs(tmp_path)
    write_sweep(tmp_path, "s1")
    eager = pointatlas.open_sweep(tmp_path)
    assert eager.encoding["source"].endswith("sweep.nc") and eager.attrs["sweep_id"] == "s1"
    with pointatlas.open_sweep(tmp_path, lazy=True) as lazy:
        assert lazy.encoding["source"].endswith("sweep.nc") and hasattr(lazy["u"].data, "dask")
        np.testing.assert_array_equal(lazy["u"].values, eager["u"].values)


def test_a_damaged_sweep_nc_is_read_from_the_jobs(tmp_path, caplog):
    import os

    from pointatlas.sweep import write_sweep

    for k, n in enumerate((10, 20, 30)):
        fake_run(tmp_path / str(k), [f"source.n_points={n}"], 1.0 / n)
    path = write_sweep(tmp_path)
    path.write_bytes(path.read_bytes()[:40])       # cut short, still the newest file
    os.utime(path, (path.stat().st_mtime + 10,) * 2)
    ds = pointatlas.open_sweep(tmp_path)
    np.testing.assert_allclose(ds["err"].values, [0.1, 0.05, 1 / 30])
    assert "could not be read" in caplog.text and "reading the 3 jobs" in caplog.text


def test_a_lazy_sweep_pads_like_the_eager_one(tmp_path):
    xr = __import__("xarray")
    for k, n in enumerate((2, 3)):
        ds = xr.Dataset({"tri": (("triangle", "corner"), np.arange(3 * n).reshape(n, 3),
                                 {"long_name": "triangles", "units": "1"}),
                         "n": ((), np.int32(n), {"long_name": "count", "units": "1"})})
        write_results(ds, tmp_path / str(k) / "results.nc",
                      {"overrides": [f"source.n_points={n}"], "status": "completed"})
    eager = pointatlas.open_sweep(tmp_path)
    with pointatlas.open_sweep(tmp_path, lazy=True) as lazy:
        for name, kind in (("tri", "f"), ("n", "i")):
            assert lazy[name].dtype == eager[name].dtype and eager[name].dtype.kind == kind
            np.testing.assert_array_equal(lazy[name].values, eager[name].values)
