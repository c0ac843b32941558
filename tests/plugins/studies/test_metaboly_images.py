"""Frames → generating curves: accuracy against known shapes, dropped frames, orientation."""
import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from pointatlas.errors import InputError
from pointatlas_sources.frame_sequence import FrameSequence
from pointatlas_sources.metaboly_strokes import stroke_shape
from pointatlas_sources.synthetic_metaboly import SyntheticMetaboly, render_frame
from pointatlas_studies.metaboly_images import (REASON_BLANK, REASON_BORDER, REASON_NOISE,
                                                flip_curve, orient_consistently,
                                                process_frames, segment)

pytest.importorskip("skimage")


def _distance_to_polyline(points, line):
    """Distance (n,) from each point to the polyline ``line`` (m, 2)."""
    a, b = line[:-1][None], line[1:][None]
    p = points[:, None]
    t = np.clip(((p - a) * (b - a)).sum(-1) / ((b - a) ** 2).sum(-1), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * (b - a)), axis=-1).min(axis=1)


def _errors(curve, true):
    """(max |r − r_true| at the same z on |z| ≤ 0.9 h, max distance to the true curve), µm."""
    h = true[0, 1]
    r, z = curve.T
    inner = np.abs(z) <= 0.9 * h
    dr = np.abs(r - np.interp(z, true[::-1, 1], true[::-1, 0]))[inner]
    return dr.max(), _distance_to_polyline(curve, true).max()


def _aligned(curve, true):
    """``curve`` or its flip, whichever is closer to ``true`` (orientation aligned)."""
    flipped = flip_curve(curve)
    return curve if _errors(curve, true)[1] <= _errors(flipped, true)[1] else flipped


@pytest.mark.parametrize("contrast", ["dark", "bright"])
def test_recovered_curves_match_the_true_shapes(contrast):
    # noise, blur, uneven illumination, rotation, drift and debris all on (their defaults)
    seq = SyntheticMetaboly(image_size=256, pixel_size=0.4, n_frames=12, n_cycles=2, debris=4,
                            contrast=contrast).load(np.random.default_rng(11))
    out = process_frames(seq)
    assert out["counts"]["kept"] == 12 and out["curves"].shape == (12, 101, 2)
    worst = np.zeros(2)
    for j, k in enumerate(out["index"]):
        true = seq.truth["shape"](seq.truth["phase"][k])
        length = 2 * true[0, 1]
        errors = _errors(_aligned(out["curves"][j], true), true)
        worst = np.maximum(worst, np.array(errors) / length)
        # the pose: axis through the true centre, along the true axis (mod 180°)
        assert np.linalg.norm(out["centre"][k] - seq.truth["centre"][k]) < 0.5
        turn = np.angle(np.exp(2j * (out["axis_angle"][k] - seq.truth["angle"][k]))) / 2
        assert abs(np.degrees(turn)) < 0.5
    assert worst.max() < 0.01, worst                     # 1 % of the body length
    assert np.nanmax(out["asymmetry"]) < 0.05


def test_an_analytic_spheroid_silhouette_drawn_without_the_renderer():
    # the silhouette of a prolate spheroid (semi-axes a, b µm) is the ellipse
    # (x/a)^2 + (y/b)^2 <= 1, rasterized here by an 8x8 supersampled inside test
    a, b, px, angle, (cx, cy) = 22.0, 7.0, 0.35, np.radians(30.0), (118.3, 101.6)
    yy, xx = np.mgrid[0:200, 0:240].astype(float)
    offsets = (np.arange(8) + 0.5) / 8 - 0.5
    inside = np.zeros_like(xx)
    for ox in offsets:
        for oy in offsets:
            dx, dy = (xx + ox - cx) * px, (yy + oy - cy) * px
            u = dx * np.cos(angle) + dy * np.sin(angle)
            v = -dx * np.sin(angle) + dy * np.cos(angle)
            inside += (u / a) ** 2 + (v / b) ** 2 <= 1.0
    image = gaussian_filter(0.6 - 0.35 * inside / 64, 1.2)
    image += 0.02 * np.random.default_rng(0).standard_normal(image.shape)
    seq = FrameSequence(frames=np.clip(image, 0, 1)[None], times=[0.0], pixel_size=px)
    out = process_frames(seq)
    r, z = out["curves"][0].T
    assert abs(z[0] - a) < 0.5 * px and abs(z[-1] + a) < 0.5 * px          # the poles
    inner = np.abs(z) <= 0.9 * a
    exact = b * np.sqrt(np.clip(1 - (z / a) ** 2, 0, None))
    assert np.abs(r - exact)[inner].max() < 0.01 * 2 * a
    assert abs(np.degrees(np.angle(np.exp(2j * (out["axis_angle"][0] - angle)))) / 2) < 0.5


def _frames_with_failures():
    seq = SyntheticMetaboly(image_size=256, pixel_size=0.4, n_frames=3, n_cycles=1).load(
        np.random.default_rng(4))
    rng = np.random.default_rng(1)
    field = np.ones((256, 256))
    touching = render_frame(stroke_shape(0.2), 0.3, (40.0, 128.0), 0.4, (256, 256),
                            (0.7, 0.35), field, 0.0, 1.0, 0.03, rng)   # crosses the left edge
    blank = np.full((256, 256), 0.6)
    noisy = np.clip(0.6 + 0.03 * rng.standard_normal((256, 256)), 0, 1)
    frames = np.concatenate([seq.frames, [touching, blank, noisy]])
    return FrameSequence(frames=frames, times=np.arange(6) * 0.5, pixel_size=0.4)


def test_frames_without_a_whole_cell_are_dropped_with_their_reason():
    seq = _frames_with_failures()
    assert segment(seq.frames[3])[0] is None and segment(seq.frames[3])[1] == REASON_BORDER
    assert segment(seq.frames[0])[0] is not None
    out = process_frames(seq)
    assert out["kept"].tolist() == [True, True, True, False, False, False]
    assert out["reason"][3] == REASON_BORDER and out["reason"][4] == REASON_BLANK
    assert out["reason"][5].startswith(REASON_NOISE)
    assert out["counts"] == {"frames": 6, "kept": 3, "dropped": 3, "by_reason": {
        REASON_BORDER: 1, REASON_BLANK: 1, REASON_NOISE: 1}}
    assert out["curves"].shape[0] == 3 and np.isnan(out["asymmetry"][3:]).all()


def test_most_frames_without_a_cell_is_an_error_naming_the_threshold():
    seq = _frames_with_failures()
    bad = FrameSequence(frames=seq.frames[[0, 3, 4, 5]], times=np.arange(4), pixel_size=0.4)
    with pytest.raises(InputError, match=r"3 of 4 frames show no cell.*Otsu thresholds? "
                                         r"around .* with a (dark|bright) cell.*cropped"):
        process_frames(bad)


def _consistent(curves, truths, margin=0.5):
    """Whether the orientation of every curve whose flip matters (by > margin µm) agrees
    with the truth in the same way (all as is, or all flipped)."""
    votes = []
    for c, t in zip(curves, truths):
        keep, flip = _errors(c, t)[1], _errors(flip_curve(c), t)[1]
        if abs(keep - flip) > margin:
            votes.append(keep < flip)
    return len(votes) > 0.5 * len(curves) and len(set(votes)) == 1


@pytest.mark.parametrize("kind", ["travelling_bulge", "euglenid_like"])
def test_shuffled_and_flipped_profiles_are_oriented_consistently(kind):
    rng = np.random.default_rng(8)
    times = np.arange(60) * 0.5 + rng.uniform(0, 0.05, 60)       # 20 frames per 10 s cycle
    truths = [stroke_shape((t / 10.0) % 1.0, kind, n_nodes=101) for t in times]
    noisy = [np.column_stack([c[:, 0] + 0.05 * rng.standard_normal(101), c[:, 1]])
             for c in truths]
    flips = rng.random(60) < 0.5
    order = rng.permutation(60)
    given = [flip_curve(noisy[k]) if flips[k] else noisy[k] for k in order]
    assert not _consistent(given, [truths[k] for k in order])    # the test can fail
    oriented, _ = orient_consistently(given, times[order])
    assert _consistent(oriented, [truths[k] for k in order])


def test_rendered_frames_rotated_by_half_turns_come_back_consistently_oriented():
    seq = SyntheticMetaboly(image_size=256, pixel_size=0.4, n_frames=40, n_cycles=2,
                            shuffle=True).load(np.random.default_rng(21))
    turned = np.random.default_rng(2).random(seq.n_frames) < 0.5
    frames = np.array([np.rot90(f, 2) if t else f for f, t in zip(seq.frames, turned)])
    out = process_frames(FrameSequence(frames=frames, times=seq.times, pixel_size=0.4))
    assert out["counts"]["kept"] == 40 and np.all(np.diff(out["times"]) > 0)
    truths = [seq.truth["shape"](seq.truth["phase"][k]) for k in out["index"]]
    assert _consistent(out["curves"], truths)
