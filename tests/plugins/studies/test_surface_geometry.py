"""The surface_geometry study through a RunContext."""
import numpy as np
import pytest

from pointatlas.context import RunContext
from pointatlas.errors import ConfigError
from pointatlas_studies.surface_geometry import SurfaceGeometry


def context(tmp_path, source="sphere", source_cfg=None, study_cfg=None):
    return RunContext(config={"source": source_cfg or {"n_points": 800},
                              "study": study_cfg or {}},
                      choices={"source": source, "study": "surface_geometry", "embedder": "pca"},
                      seed=0, run_dir=tmp_path)


def test_sphere_run(tmp_path):
    ctx = context(tmp_path)
    ds = SurfaceGeometry(**ctx.config["study"]).run(ctx)
    for v in list(ds.data_vars) + list(ds.coords):
        assert "long_name" in ds[v].attrs and "units" in ds[v].attrs, v
    assert ds["area"].attrs["reference"] == pytest.approx(4 * np.pi)
    assert float(ds["relative_error_area"]) < 5e-4
    assert float(ds["relative_error_willmore_energy"]) < 3e-3
    assert float(ds["relative_error_total_gaussian_curvature"]) < 5e-4
    assert int(ds["n_points"]) == 800 and int(ds["n_patches"]) == ds.sizes["patch"]
    assert float(ds["patch_area"].sum()) == pytest.approx(float(ds["area"]))
    assert float(ds["redundancy"]) > 1
    assert int(ds["n_unaccepted_patches"]) == 0
    for stage in ("partition", "charts", "quadrature", "integration"):
        assert stage in ctx.timings
    figs = SurfaceGeometry.report_figures(ds)
    assert figs and figs[0][0] == "Patches"


def test_torus_total_gaussian_curvature_vanishes(tmp_path):
    ctx = context(tmp_path, "torus", {"n_points": 1500})
    ds = SurfaceGeometry().run(ctx)
    assert float(ds["relative_error_area"]) < 1e-3
    assert abs(float(ds["total_gaussian_curvature"])) < 1e-2 * 4 * np.pi


def test_bad_quadrature_order_rejected(tmp_path):
    ctx = context(tmp_path, study_cfg={"quadrature_order": 0})
    with pytest.raises(ConfigError, match="order"):
        SurfaceGeometry(**ctx.config["study"]).run(ctx)
