"""The synthetic metaboly video: timing and phases, poses, rendering, drops and shuffles."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError
from pointatlas.testing import check_contract
from pointatlas_sources.metaboly_strokes import stroke_shape
from pointatlas_sources.synthetic_metaboly import (SyntheticMetaboly, coverage, cycle_times,
                                                   silhouette_polygon)

SMALL = dict(image_size=256, pixel_size=0.4, n_frames=12, n_cycles=2)


def test_registered_and_follows_the_plugin_contract():
    cls = pointatlas.load_plugin("sources", "synthetic_metaboly")
    assert cls is SyntheticMetaboly
    check_contract(cls)


def test_cycle_times_phases_follow_unequal_cycles():
    rng = np.random.default_rng(3)
    timing = cycle_times(300, 5, 10.0, 0.3, rng)
    d, starts, t, ph = timing["durations"], timing["starts"], timing["times"], timing["phase"]
    assert np.all(d >= 5.0) and np.std(d) > 0.5                  # unequal, clipped at period/2
    np.testing.assert_allclose(np.diff(t), d.sum() / 300)         # uniform in time
    assert np.all((0 <= ph) & (ph < 1))
    # phase = elapsed fraction of the frame's own cycle, recomputed independently
    for tk, pk in zip(t, ph):
        c = np.max(np.flatnonzero(starts <= tk + 1e-12))
        assert pk == pytest.approx((tk - starts[c]) / d[c], abs=1e-12)


def test_coverage_is_the_area_fraction_of_an_ellipse():
    # the renderer's area fractions against a 16x16 supersampled analytic inside test
    th = np.linspace(0, 2 * np.pi, 3000, endpoint=False)
    poly = np.column_stack([40.3 + 25 * np.cos(th), 35.7 + 12 * np.sin(th)])
    cov = coverage(poly, (72, 80))
    yy, xx = np.mgrid[0:72, 0:80]
    o = (np.arange(16) + 0.5) / 16 - 0.5
    ref = np.mean([(((xx + a - 40.3) / 25) ** 2 + ((yy + b - 35.7) / 12) ** 2 <= 1)
                   for a in o for b in o], axis=0)
    assert abs(cov.sum() - np.pi * 25 * 12) < 0.5
    assert np.abs(cov - ref).max() <= 1 / 16 + 1e-9


def test_silhouette_is_the_curve_and_its_mirror_on_the_axis():
    curve = stroke_shape(0.3, n_nodes=101)
    poly = silhouette_polygon(curve, np.pi / 2, (50.0, 60.0), 0.5)   # top pole towards +y
    assert poly[0] == pytest.approx([50.0, 60.0 + curve[0, 1] / 0.5])  # the top pole
    assert np.allclose(poly[:, 0].max() - 50.0, 50.0 - poly[:, 0].min())
    assert poly[:, 0].max() - 50.0 == pytest.approx(curve[:, 0].max() / 0.5)


def test_same_seed_same_frames_and_truth():
    a = SyntheticMetaboly(**SMALL, debris=3).load(np.random.default_rng(5))
    b = SyntheticMetaboly(**SMALL, debris=3).load(np.random.default_rng(5))
    c = SyntheticMetaboly(**SMALL, debris=3).load(np.random.default_rng(6))
    np.testing.assert_array_equal(a.frames, b.frames)
    assert not np.array_equal(a.frames, c.frames)
    assert a.frames.shape == (12, 256, 256) and a.pixel_size == 0.4
    assert 0.0 <= a.frames.min() and a.frames.max() <= 1.0
    truth = a.truth
    assert truth["period"] == pytest.approx(10.0) and len(truth["cycle_starts"]) == 2
    np.testing.assert_allclose(truth["shape"](0.25), stroke_shape(0.25))
    assert truth["angle"].shape == (12,) and truth["centre"].shape == (12, 2)
    # the pose wanders within its amplitudes (degrees, px)
    ang = np.unwrap(truth["angle"])
    assert np.ptp(np.degrees(ang)) <= 2 * 20.0 + 1e-9
    assert np.linalg.norm(truth["centre"] - 127.5, axis=1).max() <= 20.0 + 1e-9


@pytest.mark.parametrize("contrast", ["dark", "bright"])
def test_contrast_and_the_cell_never_touches_the_border(contrast):
    seq = SyntheticMetaboly(image_size=512, n_frames=4, contrast=contrast).load(
        np.random.default_rng(0))                                  # default sizes
    for frame in seq.frames:
        border = np.concatenate([frame[:4].ravel(), frame[-4:].ravel(), frame[:, :4].ravel(),
                                 frame[:, -4:].ravel()])
        centre = frame[240:272, 240:272]
        if contrast == "dark":
            assert centre.mean() < border.mean() - 0.2 and border.min() > 0.4
        else:
            assert centre.mean() > border.mean() + 0.2 and border.max() < 0.55


def test_a_cell_too_large_for_the_image_is_refused():
    with pytest.raises(ConfigError, match="would touch the border.*Raise image_size"):
        SyntheticMetaboly(image_size=128, n_frames=2).load(np.random.default_rng(0))


def test_drops_and_shuffle_keep_each_frame_with_its_time():
    plain = SyntheticMetaboly(**SMALL).load(np.random.default_rng(2))
    mixed = SyntheticMetaboly(**SMALL, drop_fraction=0.25, shuffle=True).load(
        np.random.default_rng(2))
    assert mixed.n_frames == 9 and mixed.info["frames_dropped"] == 3
    assert "drop_fraction" in mixed.info["drop_reason"]
    assert not np.all(np.diff(mixed.times) > 0)                     # not in time order
    for frame, t, k, ph in zip(mixed.frames, mixed.times, mixed.truth["frame_index"],
                               mixed.truth["phase"]):
        j = int(np.flatnonzero(np.isclose(plain.times, t))[0])
        assert j == k and ph == plain.truth["phase"][j]
        np.testing.assert_array_equal(frame, plain.frames[j])


def test_cli_composes_the_source(tmp_path):
    exe = Path(sys.executable).with_name("pointatlas")
    done = subprocess.run([str(exe), "source=synthetic_metaboly", "--cfg", "job"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "stroke: travelling_bulge" in done.stdout and "pixel_size: 0.2" in done.stdout
