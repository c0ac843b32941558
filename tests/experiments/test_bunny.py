"""`experiment=bunny_geometry` and `experiment=shell_bunny` on the Stanford bunny that ships with
pymeshlab (issue 16, item 6): they compose, and the default atlas's verdict on the scan."""
import numpy as np
import pytest

pytest.importorskip("pymeshlab")


@pytest.mark.parametrize("name", ["bunny_geometry", "shell_bunny"])
def test_bunny_experiments_compose(tmp_path, run_cli, name):
    out = run_cli("pointatlas", f"experiment={name}", "--cfg", "job", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "scale:" in out.stdout and "n_points:" in out.stdout


def test_the_default_atlas_refuses_the_creases_of_the_scan(tmp_path, run_cli):
    """Without atlas.allow_creases the atlas does not integrate curvature over the creases of
    the scanned mesh (its flat base's rim, the rims of the ears, the folds at the legs): one
    line, with locations, naming the flag."""
    out = run_cli("pointatlas", "experiment=bunny_geometry", "atlas.allow_creases=false",
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode != 0
    assert "Traceback" not in out.stderr
    lines = [ln for ln in out.stderr.splitlines() if "this cloud has creases" in ln]
    assert len(lines) == 1 and "points on creases (of 28088)" in lines[0], out.stderr[-2000:]
    assert "set atlas.allow_creases=true" in lines[0]
    assert not list(tmp_path.glob("runs/*/*/results.nc"))


@pytest.mark.slow
def test_bunny_geometry_meets_the_bar_flagged(tmp_path, run_cli):
    """Bar of issue 16: ∫K within 2 % of 4π, area within 1 % of the mesh's 0.92269, no failed
    patch, on all 28 088 points; with atlas.allow_creases (set by the experiment) the run is
    flagged completed_with_warnings and the results name the creases."""
    out = run_cli("pointatlas", "experiment=bunny_geometry", f"outputs_root={tmp_path}",
                  cwd=tmp_path, timeout=1800)
    assert out.returncode == 0, out.stderr[-2000:]
    import xarray as xr

    path = next(tmp_path.glob("runs/*/*/results.nc"))
    ds = xr.open_dataset(path)
    assert int(ds["source_points_used"]) == 28088
    assert int(ds["n_unaccepted_patches"]) == 0
    assert float(ds["total_gaussian_curvature"]) == pytest.approx(4 * np.pi, rel=2e-2)
    assert float(ds["area"]) == pytest.approx(0.92269, rel=1e-2)
    assert "kept by atlas.allow_creases=true, but this cloud has creases" in ds.attrs["warnings"]
    import pointatlas

    assert pointatlas.open_run(path).attrs["status"] == "completed_with_warnings"
