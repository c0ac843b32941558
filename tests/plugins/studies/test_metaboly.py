"""The metaboly study end to end on small synthetic sequences (a few dozen frames), its
contract variables, the report, and bad input refused in one line."""
import numpy as np
import pytest
import xarray as xr

pytest.importorskip("skimage")

SMALL = ["source.n_frames=60", "source.n_cycles=3", "source.image_size=256",
         "source.pixel_size=0.4", "embedder.n_neighbors=10", "study.n_bins=12",
         "study.n_phases=16", "study.n_material_nodes=41", "physics.n_elements=24"]


def _run(run_cli, tmp_path, experiment, *args):
    out = run_cli("pointatlas", f"experiment={experiment}", *SMALL, *args,
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    path = next(tmp_path.glob("runs/*/*/results.nc"))
    return xr.open_dataset(path), path.parent


def test_small_synthetic_sequence_meets_the_bars(run_cli, tmp_path):
    ds, run_dir = _run(run_cli, tmp_path, "metaboly_synthetic")
    assert float(ds["shape_error"]) < 0.01
    assert float(ds["period_error"]) < 0.02
    assert float(ds["speed_error"]) < 0.03
    assert int(ds["n_dropped_frames"]) == 0 and int(ds["n_cycles"]) == 2
    assert ds["generating_curve"].dims == ("phase", "node", "rz")
    assert ds["reduced_volume"].dims == ("frame",) and "time" in ds.coords
    assert ds["shear"].dims == ("phase", "lambda")
    for name in ("displacement_per_stroke", "net_rotation", "mean_power_out",
                 "mean_power_inner_outer", "efficiency_out", "efficiency_inner_outer",
                 "shear_max", "reduced_volume_min", "reduced_volume_mean", "reduced_volume_max"):
        assert np.isfinite(float(ds[name])), name
    assert float(ds["loopness"]) > 0.5
    out = run_cli("pointatlas-report", str(run_dir), cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-2000:]
    assert len(list((run_dir / "report_files").glob("*.png"))) == 4


def test_incomplete_shuffled_cluttered_sequence(run_cli, tmp_path):
    ds, _ = _run(run_cli, tmp_path, "metaboly_robustness", "source.n_frames=75",
                 "source.debris=4")
    assert int(ds["n_frames"]) == 60            # 20 % of 75 dropped by the source
    assert float(ds["shape_error"]) < 0.01
    assert float(ds["period_error"]) < 0.02
    assert float(ds["speed_error"]) < 0.03


def test_reciprocal_stroke_goes_nowhere(run_cli, tmp_path):
    ds, _ = _run(run_cli, tmp_path, "metaboly_reciprocal")
    assert abs(float(ds["displacement_per_stroke"])) < 1e-4
    assert float(ds["loopness"]) < 0.1


@pytest.mark.parametrize("args, message", [
    (("source.n_cycles=1",), "fewer than one full cycle"),
    (("embedder.n_neighbors=2",), "disconnected"),
    (("study.max_asymmetry=0.0001",), "not axisymmetric within study.max_asymmetry"),
])
def test_bad_input_one_line_no_results(run_cli, tmp_path, args, message):
    out = run_cli("pointatlas", "experiment=metaboly_synthetic", *SMALL, *args,
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode != 0
    assert "Traceback" not in out.stderr
    assert message in out.stderr, out.stderr[-2000:]
    assert not list(tmp_path.glob("runs/*/*/results.nc"))


def test_a_missing_video_is_refused(run_cli, tmp_path):
    out = run_cli("pointatlas", "experiment=metaboly_synthetic", "source=frames",
                  "source.path=/nonexistent/video.mp4", "source.pixel_size=0.2",
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode != 0 and "Traceback" not in out.stderr
    assert "/nonexistent/video.mp4" in out.stderr, out.stderr[-2000:]


def test_a_users_video_end_to_end(run_cli, tmp_path):
    """The user's path: frames rendered by the synthetic source, encoded to H.264 by ffmpeg
    (lossy), read back by source=frames at its frame rate and pixel size."""
    import imageio.v2 as imageio

    import pointatlas

    src = pointatlas.load_plugin("sources", "synthetic_metaboly")(
        n_frames=60, n_cycles=3, image_size=256, pixel_size=0.4)
    seq = src.load(np.random.default_rng(0))
    rate = 1.0 / float(np.diff(np.sort(seq.times)).mean())
    with imageio.get_writer(tmp_path / "cell.mp4", format="FFMPEG", fps=rate, codec="libx264",
                            quality=9, macro_block_size=16) as w:
        for f in seq.frames[np.argsort(seq.times)]:
            w.append_data((255 * f).astype(np.uint8))
    out = run_cli("pointatlas", "experiment=metaboly_synthetic", "source=frames",
                  f"source.path={tmp_path / 'cell.mp4'}", f"source.frame_rate={rate}",
                  "source.pixel_size=0.4", *[a for a in SMALL if not a.startswith("source.")],
                  f"outputs_root={tmp_path}", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    ds = xr.open_dataset(next(tmp_path.glob("runs/*/*/results.nc")))
    assert int(ds["n_frames"]) == 60 and int(ds["n_cycles"]) == 2
    assert float(ds["period"]) == pytest.approx(10.0, rel=0.02)
    assert "shape_error" not in ds                 # no truth for a user's video
    assert abs(float(ds["displacement_per_stroke"])) == pytest.approx(0.0102, rel=0.1)
