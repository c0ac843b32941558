"""Synthetic microscopy video of a metabolic (shape-changing) axisymmetric cell with a known
stroke: the ground truth of the metaboly pipeline (Arroyo et al., PNAS 109 (2012) 17874).

Each frame shows the silhouette of the body of revolution of a generating curve (r, z) of
:func:`metaboly_strokes.stroke_shape` seen perpendicular to its axis: the region bounded by
the curve and its mirror (−r, z), rotated to the frame's axis angle and centred at the
frame's centre (pixel coordinates x to the right, y down, pixel (i, j) centred at x = j,
y = i). The area fraction of each pixel is exact along x and sampled on 8 sub-rows along y.

Intensities: background and cell levels (``contrast``), small debris discs outside the region
the cell sweeps (some orbiting), multiplied by a smooth illumination field 1 + A g(x, y)
(g ∈ [−1, 1], a ramp in a random direction plus a vignette), Gaussian blur (σ in px),
additive Gaussian noise, clipped to [0, 1].

Timing: ``n_cycles`` cycles of durations T_c = period · max(0.5, 1 + jitter · N(0, 1)); the
``n_frames`` frames are spread uniformly over their total; a frame's phase is the elapsed
fraction of its cycle. Pose: the axis angle wanders by up to ``rotation`` degrees about a
random angle and the centre by up to ``drift`` px about the image centre (Gaussian-smoothed
random walks). Frames may then be dropped (``drop_fraction``) and shuffled (``shuffle``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.ndimage import gaussian_filter, gaussian_filter1d

from pointatlas.constraints import Interval, Options, Types, validate_parameters
from pointatlas.errors import ConfigError
from pointatlas.stores_config import stores_config

from .frame_sequence import FrameSequence
from .metaboly_strokes import STROKES, stroke_shape

#: (background, cell) intensities of each contrast
LEVELS = {"dark": (0.70, 0.35), "bright": (0.30, 0.65)}
SUB_ROWS = 8
PROFILE_NODES = 401


# -- geometry -----------------------------------------------------------------------------

def silhouette_polygon(curve: np.ndarray, angle: float, centre, pixel_size: float) -> np.ndarray:
    """Closed polygon (m, 2), pixel (x, y), of the silhouette of the body of revolution of
    ``curve`` ((n, 2) (r, z) µm, top pole first) with its top pole in direction ``angle``
    (radians from the +x image axis) and its origin at ``centre`` (px)."""
    r, z = np.asarray(curve, dtype=np.float64).T
    lateral = np.concatenate([r, -r[-2:0:-1]])       # right half down, left half back up
    axial = np.concatenate([z, z[-2:0:-1]])
    u = np.array([np.cos(angle), np.sin(angle)])      # axis direction (towards the top pole)
    w = np.array([-u[1], u[0]])                       # lateral direction
    return np.asarray(centre, float) + (np.outer(axial, u) + np.outer(lateral, w)) / pixel_size


def coverage(polygon: np.ndarray, shape: tuple[int, int], sub_rows: int = SUB_ROWS) -> np.ndarray:
    """Area fraction (H, W) of each pixel inside a simple closed ``polygon`` (m, 2) (x, y)
    in px: exact along x on each of ``sub_rows`` sub-rows per pixel row, averaged."""
    H, W = shape
    out = np.zeros(shape)
    x, y = polygon[:, 0], polygon[:, 1]
    i0, i1 = max(int(np.floor(y.min() + 0.5)), 0), min(int(np.floor(y.max() + 0.5)), H - 1)
    j0, j1 = max(int(np.floor(x.min() + 0.5)) - 1, 0), min(int(np.floor(x.max() + 0.5)) + 1, W - 1)
    if i1 < i0 or j1 < j0:
        return out
    n_rows = (i1 - i0 + 1) * sub_rows
    ys = i0 - 0.5 + (np.arange(n_rows) + 0.5) / sub_rows          # sub-row centres
    x1, y1 = x, y
    x2, y2 = np.roll(x, -1), np.roll(y, -1)
    # sub-rows k with lo <= ys[k] < hi cross the edge (half-open: a vertex counts once)
    first = np.clip(np.ceil((np.minimum(y1, y2) - i0 + 0.5) * sub_rows - 0.5), 0, n_rows)
    stop = np.clip(np.ceil((np.maximum(y1, y2) - i0 + 0.5) * sub_rows - 0.5), 0, n_rows)
    counts = (stop - first).astype(int)
    edge = np.repeat(np.arange(len(x)), counts)
    row = (first[edge] + np.arange(len(edge)) - np.repeat(np.cumsum(counts) - counts, counts)
           ).astype(int)
    t = (ys[row] - y1[edge]) / (y2[edge] - y1[edge])
    xc = x1[edge] + t * (x2[edge] - x1[edge])
    sign = np.where(y2[edge] > y1[edge], 1.0, -1.0)
    ncol = j1 - j0 + 1
    p = np.clip(np.floor(xc + 0.5).astype(int) - j0, 0, ncol)
    frac = np.clip(p + j0 + 0.5 - xc, 0.0, 1.0)
    A = np.zeros((len(ys), ncol + 2))
    B = np.zeros((len(ys), ncol + 2))
    np.add.at(A, (row, p), sign * frac)
    np.add.at(B, (row, p + 1), sign)
    cov = np.abs(A + np.cumsum(B, axis=1))[:, :ncol]
    cov = cov.reshape(i1 - i0 + 1, sub_rows, ncol).mean(axis=1)
    out[i0:i1 + 1, j0:j1 + 1] = np.clip(cov, 0.0, 1.0)
    return out


def disc_coverage(shape, centre, radius: float) -> np.ndarray:
    """Approximate area fraction (H, W) of a disc (px), linear across its edge."""
    H, W = shape
    yy, xx = np.mgrid[0:H, 0:W]
    d = np.hypot(xx - centre[0], yy - centre[1])
    return np.clip(radius + 0.5 - d, 0.0, 1.0)


# -- random processes -----------------------------------------------------------------------

def wander(n: int, dims: int, amplitude: float, rng: np.random.Generator) -> np.ndarray:
    """(n, dims) smooth random path (a Gaussian-smoothed random walk, σ = n/15 samples),
    centred and scaled so that its largest norm is ``amplitude``."""
    walk = np.cumsum(rng.normal(size=(n, dims)), axis=0)
    path = gaussian_filter1d(walk, sigma=max(n / 15.0, 1.0), axis=0, mode="nearest")
    path -= path.mean(axis=0)
    size = np.linalg.norm(path, axis=1).max()
    return path * (amplitude / size) if size > 0 else np.zeros((n, dims))


def illumination_field(shape, amplitude: float, rng: np.random.Generator) -> np.ndarray:
    """1 + A g(x, y): g ∈ [−1, 1] a ramp in a random direction plus a centred vignette."""
    H, W = shape
    yy, xx = np.mgrid[0:H, 0:W]
    u, v = (xx - (W - 1) / 2) / max(W, H), (yy - (H - 1) / 2) / max(W, H)
    a = rng.uniform(0, 2 * np.pi)
    g = np.cos(a) * u + np.sin(a) * v - rng.uniform(0.5, 1.5) * (u * u + v * v)
    g = 2.0 * (g - g.min()) / max(np.ptp(g), 1e-12) - 1.0
    return 1.0 + amplitude * g


def cycle_times(n_frames: int, n_cycles: int, period: float, jitter: float,
                rng: np.random.Generator) -> dict:
    """Cycle durations and starts (s), frame times spread uniformly over them, and the
    phase of each frame in [0, 1)."""
    durations = period * np.maximum(0.5, 1.0 + jitter * rng.normal(size=n_cycles))
    starts = np.concatenate([[0.0], np.cumsum(durations)[:-1]])
    times = np.arange(n_frames) * durations.sum() / n_frames
    cycle = np.clip(np.searchsorted(starts, times, side="right") - 1, 0, n_cycles - 1)
    phase = np.clip((times - starts[cycle]) / durations[cycle], 0.0, np.nextafter(1.0, 0.0))
    return {"times": times, "phase": phase, "cycle": cycle, "durations": durations,
            "starts": starts}


def place_debris(n: int, shape, keep_out: float, rng: np.random.Generator) -> list[dict]:
    """``n`` debris discs outside the disc of radius ``keep_out`` (px) about the image centre,
    which the cell never leaves: radius 1.5–4 px, dark or bright, half of them orbiting the
    centre (those whose orbit stays inside the image)."""
    H, W = shape
    c = np.array([(W - 1) / 2, (H - 1) / 2])
    out = []
    for _ in range(n):
        rho = rng.uniform(1.5, 4.0)
        for _ in range(200):
            pos = rng.uniform([rho + 1, rho + 1], [W - 2 - rho, H - 2 - rho])
            dist = np.linalg.norm(pos - c)
            if dist >= keep_out + rho + 1:
                break
        else:
            raise ConfigError(f"debris={n} finds no room outside the cell's region in a "
                              f"{W}x{H} px image; lower debris or raise image_size.")
        orbit_fits = dist + rho + 1 <= min(W, H) / 2 - 1
        omega = rng.uniform(-1.0, 1.0) if (orbit_fits and rng.random() < 0.5) else 0.0
        out.append({"radius": rho, "contrast": rng.choice([-1, 1]) * rng.uniform(0.15, 0.35),
                    "distance": dist, "angle": float(np.arctan2(*(pos - c)[::-1])),
                    "omega": omega, "centre": c})
    return out


def debris_image(debris: list[dict], shape, u: float) -> np.ndarray:
    """Intensity offsets (H, W) of the debris at run fraction ``u`` ∈ [0, 1)."""
    image = np.zeros(shape)
    H, W = shape
    for d in debris:
        a = d["angle"] + 2 * np.pi * d["omega"] * u
        x, y = d["centre"] + d["distance"] * np.array([np.cos(a), np.sin(a)])
        k = int(np.ceil(d["radius"])) + 2
        i0, i1 = max(int(y) - k, 0), min(int(y) + k + 1, H)
        j0, j1 = max(int(x) - k, 0), min(int(x) + k + 1, W)
        image[i0:i1, j0:j1] += d["contrast"] * disc_coverage(
            (i1 - i0, j1 - j0), (x - j0, y - i0), d["radius"])
    return image


def render_frame(curve, angle, centre, pixel_size, shape, levels, field, offsets, blur, noise,
                 rng) -> np.ndarray:
    """One frame (H, W) in [0, 1] (module doc)."""
    background, cell = levels
    cov = coverage(silhouette_polygon(curve, angle, centre, pixel_size), shape)
    image = (background + (cell - background) * cov + offsets) * field
    if blur > 0:
        image = gaussian_filter(image, blur, mode="nearest")
    if noise > 0:
        image += noise * rng.standard_normal(shape)
    return np.clip(image, 0.0, 1.0)


# -- the source -----------------------------------------------------------------------------

_POS = [Interval(float, 0, None, closed="neither")]
_NONNEG = [Interval(float, 0, None)]


@stores_config
class SyntheticMetaboly:
    """Rendered video of a cell performing a known stroke (module doc), with its truth."""

    @dataclass
    class Config:
        stroke: str = "travelling_bulge"
        length: float = 50.0            # µm, pole to pole
        radius: float = 8.0             # µm, equatorial radius of the spheroid
        amplitude: float = 0.4          # relative amplitude of the shape modes
        n_cycles: int = 4
        n_frames: int = 400
        period: float = 10.0            # s, mean cycle duration
        cycle_jitter: float = 0.0       # relative std of the cycle durations
        image_size: int = 512           # px (square frames)
        pixel_size: float = 0.2         # µm per pixel
        noise: float = 0.03             # std of additive Gaussian noise (intensities in [0, 1])
        blur: float = 1.0               # px, Gaussian σ
        illumination: float = 0.2       # amplitude A of the illumination field 1 + A g
        rotation: float = 20.0          # degrees, largest wander of the axis angle
        drift: float = 20.0             # px, largest wander of the centre
        debris: int = 0                 # number of debris particles
        drop_fraction: float = 0.0      # fraction of frames dropped at random
        shuffle: bool = False           # frames returned in random order (with their times)
        contrast: str = "dark"          # cell darker or brighter than the background

        parameter_constraints: ClassVar[dict[str, list]] = {
            "stroke": [Options(STROKES)],
            "length": _POS, "radius": _POS, "period": _POS, "pixel_size": _POS,
            "amplitude": [Interval(float, 0, 1.2)],
            "n_cycles": [Interval(int, 1, None)],
            "n_frames": [Interval(int, 1, None)],
            "cycle_jitter": [Interval(float, 0, 1)],
            "image_size": [Interval(int, 16, None)],
            "noise": _NONNEG, "blur": _NONNEG, "drift": _NONNEG,
            "illumination": [Interval(float, 0, 1, closed="left")],
            "rotation": [Interval(float, 0, 180)],
            "debris": [Interval(int, 0, None)],
            "drop_fraction": [Interval(float, 0, 1, closed="left")],
            "shuffle": [Types(bool)],
            "contrast": [Options(tuple(LEVELS))],
        }

    description: ClassVar[str] = ("Rendered microscopy frames of an axisymmetric cell performing "
                                  "a known metaboly stroke (ground truth attached).")

    def shape(self, phase: float, n_nodes: int = PROFILE_NODES) -> np.ndarray:
        """True generating curve (n_nodes, 2), (r, z) µm, top pole first, at ``phase``."""
        return stroke_shape(phase, self.stroke, self.length, self.radius, self.amplitude,
                            n_nodes)

    def check_config(self) -> None:
        validate_parameters(self)

    def _check_fit(self, curves: list[np.ndarray]) -> float:
        """Largest distance (px) of the cell from its centre; ConfigError if the cell can
        touch the border."""
        reach = max(float(np.hypot(c[:, 0], c[:, 1]).max()) for c in curves) / self.pixel_size
        room = self.image_size / 2.0 - 2.0 - 3.0 * self.blur
        if reach + self.drift > room:
            raise ConfigError(
                f"the cell reaches {reach:.0f} px from its centre and drifts {self.drift:g} px "
                f"but the {self.image_size} px image leaves {room:.0f} px: it would touch the "
                "border. Raise image_size or pixel_size, or lower drift or length.")
        return reach

    def load(self, rng: np.random.Generator) -> FrameSequence:
        """Render the frames; all randomness from ``rng``."""
        self.check_config()
        if not isinstance(rng, np.random.Generator):
            raise ConfigError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}. "
                              "Pass numpy.random.default_rng(seed).")
        n, size = int(self.n_frames), int(self.image_size)
        shape = (size, size)
        timing = cycle_times(n, int(self.n_cycles), float(self.period), float(self.cycle_jitter),
                             rng)
        try:
            curves = [self.shape(p) for p in timing["phase"]]
        except ValueError as exc:  # a stroke whose shapes cannot keep area and volume
            raise ConfigError(f"amplitude={self.amplitude!r} is invalid for stroke "
                              f"{self.stroke!r}: {exc}") from None
        reach = self._check_fit(curves)
        wobble = wander(n, 1, 1.0, rng)[:, 0]
        angles = rng.uniform(0, 2 * np.pi) + np.deg2rad(self.rotation) * wobble
        centres = np.array([(size - 1) / 2.0] * 2) + wander(n, 2, float(self.drift), rng)
        field = illumination_field(shape, float(self.illumination), rng)
        debris = place_debris(int(self.debris), shape, reach + self.drift + 2 * self.blur, rng)
        seeds = rng.integers(0, 2 ** 63, size=n)     # each frame's noise: its own stream
        keep = np.arange(n)
        n_drop = int(round(self.drop_fraction * n))
        if n_drop:
            keep = np.sort(rng.choice(n, size=n - n_drop, replace=False))
        if self.shuffle:
            keep = rng.permutation(keep)
        frames = np.empty((len(keep), size, size))   # only the kept frames are rendered
        for j, k in enumerate(keep):
            offsets = debris_image(debris, shape, k / n) if debris else 0.0
            frames[j] = render_frame(curves[k], angles[k], centres[k], self.pixel_size, shape,
                                     LEVELS[self.contrast], field, offsets, self.blur,
                                     self.noise, np.random.default_rng(seeds[k]))
        kind, length, radius, amplitude = self.stroke, self.length, self.radius, self.amplitude
        truth = {
            "phase": timing["phase"][keep], "period": float(timing["durations"].mean()),
            "cycle_durations": timing["durations"], "cycle_starts": timing["starts"],
            "cycle": timing["cycle"][keep], "frame_index": keep,
            "shape": lambda phase: stroke_shape(phase, kind, length, radius, amplitude),
            "stroke": kind, "length": length, "radius": radius, "amplitude": amplitude,
            "angle": angles[keep], "centre": centres[keep], "contrast": self.contrast,
        }
        info = {"source": "synthetic_metaboly", "frames_generated": n, "frames_read": len(keep),
                "frames_dropped": n_drop,
                "drop_reason": "dropped at random (drop_fraction)" if n_drop else "",
                "shuffled": bool(self.shuffle)}
        return FrameSequence(frames=frames, times=timing["times"][keep],
                             pixel_size=float(self.pixel_size),
                             name=f"synthetic_metaboly_{kind}", info=info, truth=truth)


__all__ = ["SyntheticMetaboly", "silhouette_polygon", "coverage", "wander", "cycle_times",
           "illumination_field", "render_frame"]
