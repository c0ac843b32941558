"""surface_geometry on clouds made here: repaired charts are recorded per patch; charts that
cannot be repaired are refused, or kept and flagged with allow_failed_patches."""
import numpy as np
import pytest

from pointatlas.context import RunContext
from pointatlas_atlas.chart_repair import AtlasError
from pointatlas_studies.surface_geometry import SurfaceGeometry

from ..atlas.implicit_surfaces import (figure_eight_box, figure_eight_tube, marching_cubes_area,
                                       sample_level_set, torus_tube)

R, r = 1.0, 0.25   # thin torus, 2 000 points: 29 spacings round the tube


@pytest.fixture(scope="module")
def torus_file(tmp_path_factory):
    X = sample_level_set(lambda x: torus_tube(x, R, r), [-R - r - 0.05] * 2 + [-r - 0.05],
                         [R + r + 0.05] * 2 + [r + 0.05], 2000)
    path = tmp_path_factory.mktemp("clouds") / "thin_torus.npz"
    np.savez(path, points=X)
    return path


def run(tmp_path, path, **study):
    cfg = {"markers_per_patch": 150, **study}
    ctx = RunContext(config={"source": {"path": str(path)}, "study": cfg, "atlas": cfg},
                     choices={"source": "file", "study": "surface_geometry", "embedder": "pca"},
                     seed=0, run_dir=tmp_path)
    return SurfaceGeometry(**cfg).run(ctx)


def test_repaired_patches_are_recorded(tmp_path, torus_file):
    ds = run(tmp_path, torus_file)
    assert int(ds["n_unaccepted_patches"]) == 0 and float(ds["unaccepted_weight_fraction"]) == 0
    assert "warnings" not in ds.attrs
    emb = ds["patch_embedder"]
    names = emb.attrs["flag_meanings"].split()
    assert names[:3] == ["pca", "nlie", "isomap"]
    assert list(emb.attrs["flag_values"]) == list(range(len(names)))
    used = [names[c] for c in emb.values]
    assert used.count("pca") < len(used) // 2         # PCA folds round the thin tube
    assert ds["patch_split_depth"].dims == ("patch",) and int(ds["patch_split_depth"].min()) >= 0
    for v in ("patch_embedder", "patch_split_depth", "unaccepted_weight_fraction"):
        assert "long_name" in ds[v].attrs and "units" in ds[v].attrs
    assert float(ds["area"]) == pytest.approx(4 * np.pi**2 * R * r, rel=1e-3)
    assert abs(float(ds["total_gaussian_curvature"])) < 1e-2 * 4 * np.pi
    assert float(ds["patch_rim_pu"].max()) <= 0.01 and ds["patch_rim_pu"].attrs["units"] == "1"


def test_a_chart_rim_carrying_weight_is_counted_and_flagged(tmp_path):
    """pyvista's ParametricEllipsoid grid with quartic charts and a 3h margin: ψ = 1 reaches
    a chart's rim (refused by default; flagged and counted with allow_failed_patches)."""
    pv = pytest.importorskip("pyvista")
    m = pv.ParametricEllipsoid(1.5, 1.0, 0.7, u_res=60, v_res=60, w_res=60)
    path = tmp_path / "ellipsoid_grid.npz"
    np.savez(path, points=np.unique(np.asarray(m.points, dtype=np.float64).round(9), axis=0))
    ds = run(tmp_path / "run", path, markers_per_patch=150, chart_reproduction="quartic",
             chart_margin=3.0, allow_failed_patches=True)
    rim = ds["patch_rim_pu"].values
    assert rim.max() > 0.01
    assert int(ds["n_unaccepted_patches"]) >= int((rim > 0.01).sum()) >= 1
    assert "rim of their domain" in ds.attrs["warnings"]


def test_failed_patches_refused_or_flagged(tmp_path, torus_file):
    strict = {"max_distortion": 1.05, "max_refinement_depth": 0}   # nothing curved passes
    with pytest.raises(AtlasError, match="patches of the atlas fail the chart test"):
        run(tmp_path / "refused", torus_file, **strict)
    ds = run(tmp_path / "allowed", torus_file, allow_failed_patches=True, **strict)
    n = int(ds["n_patches"])
    assert int(ds["n_unaccepted_patches"]) == n
    assert float(ds["unaccepted_weight_fraction"]) == pytest.approx(1.0)
    assert ds.attrs["warnings"].startswith(f"{n} of {n} patches")


def test_refusal_is_one_line_from_the_command_line(tmp_path, torus_file, run_cli):
    out = run_cli("pointatlas", "source=file", f"source.path={torus_file}",
                  "source.n_points=null", "atlas.max_distortion=1.05",
                  "atlas.max_refinement_depth=0", f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode != 0
    assert "Traceback" not in out.stderr
    lines = [ln for ln in out.stderr.splitlines() if "patches of the atlas fail" in ln]
    assert len(lines) == 1 and "atlas.allow_failed_patches=true" in lines[0]


@pytest.mark.slow
def test_genus_two_thin_tube_with_the_default_command(tmp_path, run_cli):
    """The bar of issue 16: the tube of radius 0.075 round two tangent circles of radius 0.5
    (union smoothed over 0.06), 6 000 Newton-projected, farthest-point-thinned points (28
    spacings round the tube); default command (PCA charts, repaired). ∫K within 2 % of −4π,
    area within 0.5 % of marching cubes (spacing 0.004, χ = −2), no failed patch."""
    lo, hi = figure_eight_box()
    X = sample_level_set(figure_eight_tube, lo, hi, 6000)
    reference, euler = marching_cubes_area(figure_eight_tube, lo, hi, 0.004)
    assert euler == -2                                     # genus 2
    path = tmp_path / "figure_eight.npz"
    np.savez(path, points=X)
    out = run_cli("pointatlas", "source=file", f"source.path={path}",
                  f"outputs_root={tmp_path}", cwd=tmp_path)   # the default command
    assert out.returncode == 0, out.stderr[-2000:]
    import xarray as xr

    ds = xr.open_dataset(next(tmp_path.glob("runs/*/*/results.nc")))
    print(f"genus-2 tube: int K {float(ds['total_gaussian_curvature']):.5f} (-4pi), area "
          f"{float(ds['area']):.5f} (marching cubes {reference:.5f}), "
          f"{int(ds['n_unaccepted_patches'])} failed patches, {float(ds.attrs['wall_time_s']):.1f} s")
    assert int(ds["source_points_used"]) == 6000
    assert int(ds["n_unaccepted_patches"]) == 0
    assert float(ds["total_gaussian_curvature"]) == pytest.approx(-4 * np.pi, rel=2e-2)
    assert float(ds["area"]) == pytest.approx(reference, rel=5e-3)
