"""Frames of a cell video or of a folder of images, as a grayscale :class:`FrameSequence`.

A video is decoded with ffmpeg (imageio's FFMPEG plugin, the ffmpeg binary of
imageio-ffmpeg); a folder holds one image per frame (png, jpg, tif, bmp), taken in natural
name order (``f2.png`` before ``f10.png``); a single image file (a multi-page TIFF stack)
gives its pages. Colour is converted to luminance Y = 0.2125 R + 0.7154 G + 0.0721 B, and
integers are scaled by their type's maximum (8-bit: / 255), so intensities are in [0, 1].
Frame k of the selection ``start:stop:step`` has time ``index / frame_rate`` (s), ``index``
its position in the source.
"""
from __future__ import annotations

import logging
import re
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar, Optional

import numpy as np

from pointatlas.constraints import Interval, Types, validate_parameters
from pointatlas.errors import ConfigError, InputError
from pointatlas.stores_config import stores_config

from .frame_sequence import FrameSequence, stack_frames

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp")
LUMA = np.array([0.2125, 0.7154, 0.0721])
CONVERT = "convert it with ffmpeg -i in.avi -c:v libx264 -pix_fmt yuv420p out.mp4"

log = logging.getLogger("pointatlas.sources")


def to_gray(image: np.ndarray) -> np.ndarray:
    """A 2-D image (H, W) of floats in [0, 1] from gray, RGB or RGBA pixels of any dtype
    (integers scaled by their type's maximum; floats kept as they are)."""
    a = np.asarray(image)
    integer = a.dtype.kind in "iub"
    scale = float(np.iinfo(a.dtype).max) if a.dtype.kind in "iu" else 1.0
    a = a.astype(np.float64)
    if a.ndim == 3 and a.shape[-1] in (3, 4):
        a = a[..., :3] @ LUMA
    elif a.ndim == 3 and a.shape[-1] in (1, 2):  # gray (+ alpha)
        a = a[..., 0]
    if a.ndim != 2:
        raise ValueError(f"pixels of shape {a.shape} are not one gray or colour image")
    return np.clip(a / scale, 0.0, 1.0) if integer else a


def pages(image: np.ndarray) -> list[np.ndarray]:
    """The 2-D gray frames of a decoded image file: one for a gray/colour image, one per page
    of a stack (P, H, W) or (P, H, W, C)."""
    a = np.asarray(image)
    if a.ndim == 2 or (a.ndim == 3 and a.shape[-1] in (1, 2, 3, 4)):
        return [to_gray(a)]
    if a.ndim in (3, 4):
        return [to_gray(p) for p in a]
    raise ValueError(f"pixels of shape {a.shape} are not an image or a stack of images")


def natural_key(path: Path):
    """Sort key of a file name with its digit runs compared as numbers."""
    return [int(t) if t.isdigit() else t.lower() for t in re.split(r"(\d+)", path.name)]


def ffmpeg_reason(exc: BaseException) -> str:
    """ffmpeg's short reason from an imageio error: its last informative stderr lines,
    without version banners, ``[in#0 @ 0x…]`` prefixes and the file name."""
    lines = [line.strip() for line in str(exc).splitlines()]
    if "=== stderr ===" in lines:
        lines = lines[lines.index("=== stderr ===") + 1:]
    keep = []
    for line in lines:
        line = re.sub(r"^\[[^\]]*@ 0x[0-9a-fA-F]+\]\s*", "", line)
        if (not line or line.startswith(("ffmpeg version", "built with", "configuration:",
                                          "lib", "Input #", "Stream", "Metadata", "Duration"))
                or "misdetection possible" in line or line.startswith("Error opening input file ")):
            continue
        line = line.replace("Error opening input files: ", "").replace("Error opening input: ", "")
        if line not in keep:
            keep.append(line)
    if not keep:
        return str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return "; ".join(keep[-2:])


def open_video(path: Path):
    """imageio's ffmpeg reader of ``path``; InputError with ffmpeg's reason if it refuses."""
    import imageio.v2 as iio

    try:
        return iio.get_reader(str(path), format="FFMPEG")
    except Exception as exc:  # noqa: BLE001 - ffmpeg refused the file
        raise InputError(f"{path} cannot be decoded by ffmpeg ({ffmpeg_reason(exc)}); check that "
                         f"it is a video, or {CONVERT}.") from None


def read_video(path: Path, start: int, stop: Optional[int], step: int):
    """Selected gray frames of a video, their indices in the video, the container's frame
    rate (Hz or None), the read error that ended the stream early (or None) and the number
    of frames scanned."""
    reader = open_video(path)
    frames, indices, error = [], [], None
    try:
        fps = reader.get_meta_data().get("fps")
        k = -1
        iterator = iter(reader)
        while stop is None or k + 1 < stop:
            try:
                image = next(iterator)
            except StopIteration:
                break
            except Exception as exc:  # noqa: BLE001 - a stream broken mid-way
                error = ffmpeg_reason(exc)
                break
            k += 1
            if k >= start and (k - start) % step == 0:
                frames.append(to_gray(image))
                indices.append(k)
    finally:
        reader.close()
    if not frames and error is not None:
        raise InputError(f"{path} cannot be decoded by ffmpeg ({error}); {CONVERT}.")
    return frames, indices, (float(fps) if fps else None), error, k + 1


def read_folder(folder: Path, start: int, stop: Optional[int], step: int):
    """Selected gray frames of the images of ``folder`` (natural name order), their indices,
    their file names and the number of images in the folder."""
    import imageio.v3 as iio

    files = sorted((p for p in folder.iterdir()
                    if p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES), key=natural_key)
    if not files:
        raise InputError(f"{folder} holds no images ({', '.join(IMAGE_SUFFIXES)}); give a "
                         "folder of frames or a video file as source.path.")
    chosen = list(range(len(files)))[start:stop:step]
    frames, names = [], []
    for k in chosen:
        try:
            found = pages(iio.imread(files[k]))
        except Exception as exc:  # noqa: BLE001 - any failure is the user's file
            raise InputError(f"{files[k]} cannot be read as an image ({type(exc).__name__}: "
                             f"{exc}); re-export it or remove it from the folder.") from None
        if len(found) != 1:
            raise InputError(f"{files[k]} holds {len(found)} images (a stack) in a folder of "
                             "frames; give the stack itself as source.path, or one image per "
                             "file.")
        frames += found
        names.append(str(files[k]))
    return frames, chosen, names, len(files)


def read_stack(path: Path, start: int, stop: Optional[int], step: int):
    """Selected gray pages of one image file (a TIFF stack or a single image)."""
    import imageio.v3 as iio

    try:
        found = pages(iio.imread(path))
    except Exception as exc:  # noqa: BLE001
        raise InputError(f"{path} cannot be read as an image ({type(exc).__name__}: {exc}); "
                         "re-export it, or give a folder of frames or a video.") from None
    chosen = list(range(len(found)))[start:stop:step]
    return [found[k] for k in chosen], chosen, len(found)


def _scale_floats(frames: list[np.ndarray], path: Path) -> tuple[list[np.ndarray], bool]:
    """Float images outside [0, 1] rescaled together by the sequence's min and max."""
    low = min(float(f.min()) for f in frames)
    high = max(float(f.max()) for f in frames)
    if low >= 0.0 and high <= 1.0:
        return frames, False
    if not (np.isfinite(low) and np.isfinite(high)) or high <= low:
        raise InputError(f"{path}: intensities are not finite or all equal ({low}..{high}); "
                         "give images with finite, varying intensities.")
    return [(f - low) / (high - low) for f in frames], True


@stores_config
class Frames:
    """Grayscale frames of a video (any format ffmpeg decodes), a folder of images or an
    image stack (module doc); time of a frame = its index in the source / ``frame_rate``."""

    @dataclass
    class Config:
        #: a video file, a folder of images (png, jpg, tif, bmp) or a multi-page TIFF
        path: str = "???"
        #: frames per second (Hz); None: the video's own rate (required for images)
        frame_rate: Optional[float] = None
        #: µm per pixel, from the microscope calibration (required)
        pixel_size: Optional[float] = None
        #: first frame read (index in the source)
        start: int = 0
        #: read up to this index (excluded); None: to the end
        stop: Optional[int] = None
        #: keep one frame in ``step``
        step: int = 1

        parameter_constraints: ClassVar[dict[str, list]] = {
            "path": [Types(str)],
            "frame_rate": [Interval(float, 0, None, closed="neither"), None],
            "pixel_size": [Interval(float, 0, None, closed="neither"), None],
            "start": [Interval(int, 0, None)],
            "stop": [Interval(int, 1, None), None],
            "step": [Interval(int, 1, None)],
        }

    description: ClassVar[str] = ("Grayscale frames of a cell video (ffmpeg) or a folder of "
                                  "images, with times and pixel size.")

    def check_config(self) -> Path:
        """The checks that decode no frame: settings, a pixel size, an existing path, a frame
        rate for images, a video whose header ffmpeg reads."""
        validate_parameters(self)
        if str(self.path) in ("", "???"):
            raise ConfigError("path is missing: the 'frames' source needs path=<video or folder "
                              "of images>, e.g. source.path=data/cell.mp4.")
        if self.pixel_size is None:
            raise ConfigError("pixel_size is missing: give source.pixel_size=<µm per pixel> "
                              "from the microscope calibration, e.g. source.pixel_size=0.2.")
        if self.stop is not None and self.stop <= self.start:
            raise ConfigError(f"stop={self.stop} is invalid: it must be above start="
                              f"{self.start}, or null to read to the end.")
        path = Path(self.path).expanduser()
        if not path.exists():
            raise InputError(f"{path}: no such file or folder. Check the path (relative paths "
                             f"are resolved from the working directory {Path.cwd()}).")
        if path.is_file() and path.stat().st_size == 0:
            raise InputError(f"{path} is empty (0 bytes); check that it was copied completely.")
        images = path.is_dir() or path.suffix.lower() in IMAGE_SUFFIXES
        if images and self.frame_rate is None:
            raise ConfigError("frame_rate is missing: images do not say their frame rate; give "
                              "source.frame_rate=<frames per second>, e.g. 10.")
        if not images:
            open_video(path).close()    # ffmpeg reads the header: refused before any work
        return path

    def load(self, rng: np.random.Generator | None = None) -> FrameSequence:  # noqa: ARG002
        """Read and convert the selected frames (deterministic: ``rng`` is not used)."""
        path = self.check_config()
        start, stop, step = int(self.start), self.stop, int(self.step)
        info: dict = {"source": str(path), "frames_dropped": 0, "drop_reason": ""}
        names, fps, error = None, None, None
        if path.is_dir():
            frames, indices, names, total = read_folder(path, start, stop, step)
            info.update(kind="folder", frames_in_source=total)
        elif path.suffix.lower() in IMAGE_SUFFIXES:
            frames, indices, total = read_stack(path, start, stop, step)
            info.update(kind="image stack", frames_in_source=total)
        else:
            frames, indices, fps, error, total = read_video(path, start, stop, step)
            info.update(kind="video", frames_scanned=total, video_fps=fps)
            if error is not None:
                info.update(read_error=error)
                log.warning("source %s: the video stream ended with an error after %d frames "
                            "(%s); using the frames read so far", path, total, error)
        if not frames:
            raise InputError(f"{path}: no frame in start={start}, stop={stop}, step={step} "
                             f"(the source has {total}); lower source.start.")
        rate = self.frame_rate if self.frame_rate is not None else fps
        if rate is None:
            raise ConfigError(f"frame_rate is missing: the video {path} does not say its frame "
                              "rate; give source.frame_rate=<frames per second>, e.g. 10.")
        frames, rescaled = _scale_floats(frames, path)
        info.update(frames_read=len(frames), frame_rate=float(rate), rescaled=rescaled)
        return FrameSequence(frames=stack_frames(frames, names), times=np.asarray(indices) / rate,
                             pixel_size=float(self.pixel_size), name=path.stem or path.name,
                             info=info)


__all__ = ["Frames", "to_gray", "pages", "ffmpeg_reason", "open_video", "read_video",
           "read_folder", "read_stack"]
