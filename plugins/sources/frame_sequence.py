"""A grayscale image sequence with times: what the ``frames`` and ``synthetic_metaboly``
sources return (stage 1 of the metaboly pipeline, Arroyo et al., PNAS 109 (2012) 17874)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from pointatlas.errors import InputError


def stack_frames(frames, names=None) -> np.ndarray:
    """(K, H, W) float64 from a (K, H, W) array or a list of 2-D arrays of one size.

    ``names``: a label per frame (file names) used in the message when sizes differ.
    :class:`InputError` names the first frame whose size differs from the first one's.
    """
    if isinstance(frames, np.ndarray):
        array = frames
    else:
        frames = list(frames)
        if not frames:
            raise InputError("the frame sequence is empty: give at least one frame.")
        shapes = [np.shape(f) for f in frames]
        for k, shape in enumerate(shapes):
            if shape != shapes[0]:
                what = names[k] if names is not None else f"frame {k}"
                first = names[0] if names is not None else "frame 0"
                raise InputError(
                    f"{what} is {_size(shape)} but {first} is {_size(shapes[0])}: all frames "
                    "must have one size. Crop or resize them to one size (e.g. "
                    "ffmpeg -i in -vf crop=W:H:X:Y out) or remove the odd file.")
        array = np.stack([np.asarray(f) for f in frames])
    array = np.asarray(array, dtype=np.float64)
    if array.ndim != 3:
        raise InputError(f"frames have shape {array.shape}: expected (n_frames, height, width) "
                         "grayscale images. Convert colour frames to gray first.")
    if array.shape[0] == 0 or array.shape[1] < 2 or array.shape[2] < 2:
        raise InputError(f"frames have shape {array.shape}: need at least one frame of at "
                         "least 2x2 pixels.")
    return array


def _size(shape) -> str:
    """``640x480`` (width x height) of an image shape (H, W[, C])."""
    if len(shape) >= 2:
        return f"{shape[1]}x{shape[0]} px"
    return f"of shape {tuple(shape)}"


@dataclass
class FrameSequence:
    """K grayscale frames of one cell, each with its time.

    Attributes
    ----------
    frames : (K, H, W) float64 intensities in [0, 1]
    times : (K,) seconds, finite (not necessarily sorted: a shuffled sequence keeps each
        frame's own time)
    pixel_size : µm per pixel (> 0)
    name : a short label for reports
    info : how the frames were obtained (``source``: path or generator, ``frames_read``,
        ``frames_dropped`` by the source and ``drop_reason``...)
    truth : None for measured data; for synthetic data a dict with at least ``phase`` (K,)
        true phase in [0, 1) of each frame, ``period`` (mean cycle duration, s),
        ``cycle_starts`` (s), ``shape`` (callable phase -> (n, 2) true generating curve
        (r, z) in µm, top pole first) and the stroke parameters
    """

    frames: np.ndarray
    times: np.ndarray
    pixel_size: float = 1.0
    name: str = "frames"
    info: dict = field(default_factory=dict)
    truth: Optional[dict[str, Any]] = None

    def __post_init__(self):
        self.frames = stack_frames(self.frames)
        if not np.isfinite(self.frames).all():
            raise InputError(f"{self.name}: frames hold NaN or infinite intensities; give "
                             "finite intensities in [0, 1].")
        low, high = float(self.frames.min()), float(self.frames.max())
        if low < 0.0 or high > 1.0:
            raise InputError(f"{self.name}: intensities span [{low:g}, {high:g}], outside "
                             "[0, 1]; rescale them, e.g. frames / 255 for 8-bit images.")
        self.times = np.asarray(self.times, dtype=np.float64).reshape(-1)
        if len(self.times) != len(self.frames):
            raise InputError(f"{self.name}: {len(self.times)} times for {len(self.frames)} "
                             "frames; give one time per frame.")
        if not np.isfinite(self.times).all():
            bad = np.flatnonzero(~np.isfinite(self.times))[:5].tolist()
            raise InputError(f"{self.name}: times of frames {bad} are not finite; give a "
                             "finite time (s) for every frame.")
        size = self.pixel_size
        if isinstance(size, bool) or not np.isscalar(size) or not np.isfinite(size) \
                or size <= 0:
            raise InputError(f"{self.name}: pixel_size={size!r} is invalid: it must be a "
                             "number > 0 (µm per pixel).")
        self.pixel_size = float(size)

    @property
    def n_frames(self) -> int:
        return self.frames.shape[0]

    @property
    def shape(self) -> tuple[int, int]:
        """(height, width) of the frames in pixels."""
        return self.frames.shape[1], self.frames.shape[2]

    def order(self) -> np.ndarray:
        """Frame indices in time order (stable)."""
        return np.argsort(self.times, kind="stable")


__all__ = ["FrameSequence", "stack_frames"]
