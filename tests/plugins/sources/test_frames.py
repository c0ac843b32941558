"""The frames source: folders of images, videos through ffmpeg, and the errors a user meets."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas.testing import check_contract
from pointatlas_sources.frame_sequence import FrameSequence
from pointatlas_sources.frames import Frames, ffmpeg_reason

iio = pytest.importorskip("imageio.v3")


def _images(folder, n=6, size=(40, 56), seed=0):
    rng = np.random.default_rng(seed)
    folder.mkdir(exist_ok=True)
    images = (rng.random((n, *size)) * 255).astype(np.uint8)
    for k, image in enumerate(images):
        iio.imwrite(folder / f"frame{k}.png", image)
    return images


def test_registered_and_follows_the_plugin_contract():
    assert pointatlas.load_plugin("sources", "frames") is Frames
    check_contract(Frames)


def test_folder_of_pngs_in_natural_order_with_times_from_the_frame_rate(tmp_path):
    images = _images(tmp_path / "f", n=12)          # frame10.png sorts after frame9.png
    seq = Frames(path=str(tmp_path / "f"), frame_rate=4.0, pixel_size=0.25, start=1,
                 step=3).load()
    assert isinstance(seq, FrameSequence) and seq.pixel_size == 0.25
    assert seq.frames.shape == (4, 40, 56)
    np.testing.assert_allclose(seq.times, [1 / 4, 4 / 4, 7 / 4, 10 / 4])
    np.testing.assert_allclose(seq.frames, images[1::3] / 255.0)
    assert seq.info["frames_in_source"] == 12 and seq.info["frames_read"] == 4


def test_colour_images_become_luminance(tmp_path):
    rgb = np.zeros((8, 9, 3), np.uint8)
    rgb[..., 1] = 255                                   # pure green
    (tmp_path / "c").mkdir()
    iio.imwrite(tmp_path / "c" / "a.png", rgb)
    seq = Frames(path=str(tmp_path / "c"), frame_rate=1.0, pixel_size=1.0).load()
    np.testing.assert_allclose(seq.frames, 0.7154)


def test_video_written_by_ffmpeg_is_read_back(tmp_path):
    pytest.importorskip("imageio_ffmpeg")
    import imageio.v2 as iio2

    path = tmp_path / "cell.mp4"
    yy, xx = np.mgrid[0:64, 0:96]
    writer = iio2.get_writer(str(path), format="FFMPEG", fps=8, codec="libx264",
                             macro_block_size=16, output_params=["-crf", "10"])
    for k in range(7):
        writer.append_data(((xx + 5 * k) % 96 * 2).astype(np.uint8))   # a moving ramp
    writer.close()
    seq = Frames(path=str(path), pixel_size=0.5).load()
    assert seq.frames.shape == (7, 64, 96)
    np.testing.assert_allclose(seq.times, np.arange(7) / 8.0)         # the video's own rate
    assert seq.info["kind"] == "video" and seq.info["video_fps"] == pytest.approx(8.0)
    expected = ((xx + 5 * 3) % 96 * 2) / 255.0
    assert np.median(np.abs(seq.frames[3] - expected)) < 0.03         # lossy, but the frame
    seq = Frames(path=str(path), pixel_size=0.5, frame_rate=2.0, start=2, stop=6).load()
    np.testing.assert_allclose(seq.times, [1.0, 1.5, 2.0, 2.5])


def test_images_of_different_sizes_name_the_file(tmp_path):
    _images(tmp_path / "f", n=4)
    iio.imwrite(tmp_path / "f" / "frame2.png", np.zeros((41, 56), np.uint8))
    with pytest.raises(InputError, match=r"frame2\.png is 56x41 px but .*frame0\.png is "
                                         r"56x40 px.*one size"):
        Frames(path=str(tmp_path / "f"), frame_rate=1.0, pixel_size=1.0).load()


def test_corrupt_video_is_one_line_naming_ffmpeg_and_the_fix(tmp_path):
    bad = tmp_path / "broken.mp4"
    bad.write_bytes(np.random.default_rng(0).bytes(4096))
    with pytest.raises(InputError) as caught:
        Frames(path=str(bad), pixel_size=1.0).load()
    message = str(caught.value)
    assert "\n" not in message and "Traceback" not in message
    assert "ffmpeg version" not in message and "configuration:" not in message
    assert message.startswith(str(bad)) and "cannot be decoded by ffmpeg" in message
    assert "Invalid data" in message and "ffmpeg -i in.avi -c:v libx264" in message
    with pytest.raises(InputError, match="cannot be decoded by ffmpeg"):
        Frames(path=str(bad), pixel_size=1.0).check_config()      # refused at start-up


def test_ffmpeg_reason_keeps_the_last_informative_lines():
    text = ("Could not load meta information\n=== stderr ===\n\nffmpeg version n9 Copyright\n"
            "  libavutil 61\n[in#0 @ 0x55d] moov atom not found\n[in#0 @ 0x56a] Error opening "
            "input: Invalid data found when processing input\nError opening input file x.mp4.\n")
    assert ffmpeg_reason(OSError(text)) == ("moov atom not found; Invalid data found when "
                                            "processing input")


def test_empty_folder_missing_path_and_missing_settings(tmp_path):
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.txt").write_text("no images here")
    with pytest.raises(InputError, match="holds no images"):
        Frames(path=str(tmp_path / "empty"), frame_rate=1.0, pixel_size=1.0).load()
    with pytest.raises(InputError, match="no such file or folder"):
        Frames(path=str(tmp_path / "nope.mp4"), pixel_size=1.0).load()
    with pytest.raises(ConfigError, match="path is missing"):
        Frames(pixel_size=1.0).load()
    _images(tmp_path / "f", n=2)
    with pytest.raises(ConfigError, match="pixel_size is missing"):
        Frames(path=str(tmp_path / "f"), frame_rate=1.0).load()
    with pytest.raises(ConfigError, match="frame_rate is missing"):
        Frames(path=str(tmp_path / "f"), pixel_size=1.0).load()
    with pytest.raises(ConfigError, match=r"frame_rate=-2\.0 is invalid"):
        Frames(path=str(tmp_path / "f"), pixel_size=1.0, frame_rate=-2.0).load()


def test_frame_sequence_refuses_frames_of_different_sizes_and_bad_times():
    with pytest.raises(InputError, match="frame 1 is 5x4 px but frame 0 is 5x5 px"):
        FrameSequence(frames=[np.zeros((5, 5)), np.zeros((4, 5))], times=[0, 1])
    with pytest.raises(InputError, match="not finite"):
        FrameSequence(frames=np.zeros((2, 5, 5)), times=[0, np.nan])
    with pytest.raises(InputError, match="outside"):
        FrameSequence(frames=np.full((1, 5, 5), 2.0), times=[0])
