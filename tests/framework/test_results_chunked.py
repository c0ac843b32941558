"""Large results are written in ~1 MiB netCDF chunks and can be opened lazily (issue 24)."""
import sys

import netCDF4
import numpy as np
import pytest
import xarray as xr

import pointatlas
from pointatlas.errors import ConfigError, InputError, SchemaError
from pointatlas.results import (
    CHUNK_BYTES, CHUNK_MIN_ELEMENTS, chunk_shape, storage_encoding, write_netcdf_atomic,
    write_results,
)

N = 2 * 10**6
ATTRS = {"Conventions": "CF-1.10", "title": "t", "source": "pointatlas", "history": "",
         "config": "", "overrides": [], "git_commit": "", "seed": 0, "hostname": "h",
         "wall_time_s": 0.0, "status": "completed"}


def large_dataset() -> xr.Dataset:
    rng = np.random.default_rng(7)
    return xr.Dataset(
        {"u": (("point",), rng.normal(size=N), {"long_name": "u", "units": "m"}),
         "label": (("point",), (np.arange(N) % 7).astype(np.int32),
                   {"long_name": "label", "units": "1"}),
         "xyz": (("node", "dim"), rng.normal(size=(100_000, 3)),
                 {"long_name": "xyz", "units": "m"}),
         "small": (("k",), np.arange(10.0), {"long_name": "small", "units": "m"}),
         "area": ((), 12.5, {"long_name": "area", "units": "m2"})},
    )


def chunking(path, name):
    with netCDF4.Dataset(path) as nc:
        return nc.variables[name].chunking()


@pytest.mark.parametrize("shape, itemsize, expected", [
    ((2_000_000,), 8, (131072,)),           # float64: exactly 1 MiB
    ((2_000_000,), 4, (262144,)),           # int32: also 1 MiB
    ((100_000,), 8, (100_000,)),            # smaller than 1 MiB: one chunk, whole
    ((10**6, 3), 8, (43690, 3)),            # whole along the others
    ((10_000, 100), 8, (1310, 100)),        # rows of 800 B: 1310 of them
    ((10, 200_000), 8, (1, 131072)),        # one row (1.6 MB) > 1 MiB: cut the next dim
    ((3, 2, 10**6), 8, (1, 1, 131072)),
    ((), 8, ()),
])
def test_chunk_shape(shape, itemsize, expected):
    chunks = chunk_shape(shape, itemsize)
    assert chunks == expected
    assert all(1 <= c <= n for c, n in zip(chunks, shape))
    assert itemsize * np.prod(chunks) <= CHUNK_BYTES


def test_chunk_shape_other_target_and_huge_items():
    assert chunk_shape((1000,), 8, target_bytes=800) == (100,)
    assert chunk_shape((1000, 7), 16, target_bytes=8) == (1, 1)   # element > target: 1


def test_large_variables_are_chunked_small_ones_contiguous(tmp_path):
    path = write_results(large_dataset(), tmp_path, ATTRS)
    assert chunking(path, "u") == [131072]
    assert chunking(path, "label") == [262144]
    assert chunking(path, "xyz") == [43690, 3]
    for name in ("u", "label", "xyz"):
        with netCDF4.Dataset(path) as nc:
            var = nc.variables[name]
            chunk_bytes = var.dtype.itemsize * np.prod(var.chunking())
            assert CHUNK_BYTES / 2 < chunk_bytes <= CHUNK_BYTES
            assert not var.filters()["zlib"]
    assert chunking(path, "small") == "contiguous"
    assert chunking(path, "area") == "contiguous"


def test_existing_encoding_is_respected_and_stale_one_dropped(tmp_path):
    ds = large_dataset()[["u", "small"]]
    ds["u"].encoding = {"chunksizes": (50_000,), "zlib": True, "complevel": 1}
    path = write_netcdf_atomic(ds, tmp_path / "a.nc")
    assert chunking(path, "u") == [50_000]
    with netCDF4.Dataset(path) as nc:
        assert nc.variables["u"].filters()["zlib"]
    assert ds["u"].encoding == {"chunksizes": (50_000,), "zlib": True, "complevel": 1}

    # read back, sliced to fewer points than a stale chunk: the stale layout is replaced
    with xr.open_dataset(path) as back:
        part = back.isel(point=slice(0, 70_000)).load()
    assert part["u"].encoding["original_shape"] == (N,)
    out = write_netcdf_atomic(part, tmp_path / "b.nc")
    assert chunking(out, "u") == [70_000]
    with netCDF4.Dataset(out) as nc:
        assert nc.variables["u"].filters()["zlib"]  # the compression chosen before is kept
    np.testing.assert_array_equal(xr.open_dataset(out)["u"].values, ds["u"].values[:70_000])


def test_stale_chunks_on_a_small_variable_and_explicit_contiguous(tmp_path):
    var = xr.Variable(("q",), np.arange(10.0), encoding={"chunksizes": (50,)})
    assert "chunksizes" not in storage_encoding(var)
    big = xr.Variable(("p",), np.zeros(CHUNK_MIN_ELEMENTS), encoding={"contiguous": True})
    assert storage_encoding(big) == {"contiguous": True}
    old = xr.Variable(("p",), np.zeros(CHUNK_MIN_ELEMENTS),
                      encoding={"contiguous": True, "original_shape": (CHUNK_MIN_ELEMENTS,)})
    assert storage_encoding(old)["chunksizes"] == (CHUNK_MIN_ELEMENTS,)
    assert "contiguous" not in storage_encoding(old)
    text = xr.Variable(("p",), np.array(["a"] * CHUNK_MIN_ELEMENTS, dtype=object))
    assert storage_encoding(text) == {}
    ds = xr.Dataset({"big": big, "small": var})
    path = write_netcdf_atomic(ds, tmp_path / "c.nc")
    assert chunking(path, "big") == "contiguous" and chunking(path, "small") == "contiguous"


def test_lazy_open_reads_the_written_values(tmp_path):
    ds = large_dataset()
    write_results(ds, tmp_path, ATTRS)
    with pointatlas.open_run(tmp_path, lazy=True) as lazy:
        for name in ("u", "label", "xyz"):
            assert lazy[name].chunks is not None
        assert lazy["u"].chunks == ((131072,) * 15 + (N - 15 * 131072,),)
        assert lazy["xyz"].chunks[1] == (3,)
        assert float(lazy["u"].mean()) == pytest.approx(float(ds["u"].mean()), rel=1e-12)
        assert int(lazy["label"].sum()) == int(ds["label"].sum())
        np.testing.assert_array_equal(lazy["u"][1_234_567:1_234_600].values,
                                      ds["u"].values[1_234_567:1_234_600])
        np.testing.assert_array_equal(lazy["xyz"][-5:].values, ds["xyz"].values[-5:])
        assert float(lazy["area"]) == 12.5
        assert lazy.attrs["pointatlas_schema"] == 1 and lazy.attrs["title"] == "t"
    eager = pointatlas.open_run(tmp_path)
    assert eager["u"].chunks is None
    np.testing.assert_array_equal(eager["u"].values, ds["u"].values)


def test_lazy_open_keeps_the_checks(tmp_path):
    (tmp_path / "results.nc").write_bytes(b"")
    with pytest.raises(InputError, match="is empty"):
        pointatlas.open_run(tmp_path, lazy=True)
    (tmp_path / "results.nc").write_bytes(b"CDF\x01" + b"\x00garbage" * 20)
    with pytest.raises(InputError, match="not a readable netCDF file"):
        pointatlas.open_run(tmp_path, lazy=True)
    with pytest.raises(InputError, match="no results file"):
        pointatlas.open_run(tmp_path / "missing", lazy=True)
    newer = xr.Dataset(attrs={"pointatlas_schema": 99})
    newer.to_netcdf(tmp_path / "results.nc")
    with pytest.raises(SchemaError, match="newer.*Upgrade"):
        pointatlas.open_run(tmp_path, lazy=True)
    xr.Dataset({"a": ((), 1.0)}).to_netcdf(tmp_path / "results.nc")
    with pytest.raises(SchemaError, match="not a pointatlas results file"):
        pointatlas.open_run(tmp_path, lazy=True)


def test_lazy_open_without_dask_names_the_install(tmp_path, monkeypatch):
    write_results(large_dataset()[["small"]], tmp_path, ATTRS)
    monkeypatch.setitem(sys.modules, "dask", None)
    monkeypatch.setitem(sys.modules, "dask.array", None)
    with pytest.raises(ConfigError, match=r"pip install 'pointatlas\[distributed\]'") as err:
        pointatlas.open_run(tmp_path, lazy=True)
    assert "\n" not in str(err.value)
    assert pointatlas.open_run(tmp_path)["small"].shape == (10,)  # eager needs no dask
