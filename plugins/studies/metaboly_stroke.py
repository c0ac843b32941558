"""The stroke in shape space (stages 5–6 of the metaboly pipeline).

Arroyo, Heltai, Millán & DeSimone, PNAS 109 (2012) 17874, "Shape analysis": the frames'
shape descriptors, embedded by Isomap in 2-D, lie on a closed curve (a back-and-forth arc for
a reciprocal stroke). Cycles are read from the first embedding coordinate y₁ in time order:
a cycle starts where y₁ rises through its median after having been below
median − ``hysteresis`` × range (crossing times interpolated linearly between frames), so
noise near the level does not start spurious cycles. The area swept per cycle by the
time-ordered embedding, relative to that of a circle of the same extent in y₁ (π/4 range²),
says whether the stroke is a loop (≈ 1) or a back-and-forth arc (≈ 0; ``loop`` below 0.1).
On an arc each frame's phase is its time fraction within its cycle (frames of the partial
cycles at both ends use the mean period). On a loop the angle of the embedding about its
centre labels the shape; the time reparametrisation τ maps it to the mean, over the complete
cycles, of the time fraction reached at that angle, which merges cycles of unequal duration
into one average stroke.

The smooth stroke: local max-ent (LME) basis functions p_a(φ) on ``n_bins`` periodic nodes
φ_a = a/n_bins (the nodes copied at φ_a ± 1 and their basis functions folded back), and nodal
shapes X_a fitted to the frames by least squares, X(φ) = Σ p_a(φ) X_a, dX/dφ = Σ p_a′(φ) X_a.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pointatlas.errors import InputError


@dataclass
class Cycles:
    """Cycle start times, the mean period, each frame's phase, the area swept per cycle
    (``winding``, 1 for a circle) and whether that makes a loop or an arc."""

    starts: np.ndarray
    period: float
    phase: np.ndarray
    winding: float
    loop: bool

    @property
    def n_cycles(self) -> int:
        return len(self.starts) - 1

    @property
    def durations(self) -> np.ndarray:
        return np.diff(self.starts)


def find_cycles(Y: np.ndarray, times: np.ndarray, hysteresis: float = 0.25) -> Cycles:
    """Cycles of a stroke from its embedding ``Y`` (K, ≥ 2) and the frames' ``times`` (K,),
    frames in any order (module doc). InputError when less than one cycle is found."""
    order = np.argsort(times)
    t, y = np.asarray(times, float)[order], np.asarray(Y, float)[order]
    y1 = y[:, 0]
    level, span = np.median(y1), np.ptp(y1)
    low = level - hysteresis * span
    starts, armed = [], False
    for k in range(1, len(t)):
        if y1[k - 1] < low:
            armed = True
        if armed and y1[k - 1] < level <= y1[k]:
            w = (level - y1[k - 1]) / (y1[k] - y1[k - 1])
            starts.append(t[k - 1] + w * (t[k] - t[k - 1]))
            armed = False
    inside = (t >= starts[0]) & (t <= starts[-1]) if len(starts) >= 2 else t == t
    c = y[inside, :2] - y[inside, :2].mean(axis=0)
    swept = 0.5 * np.sum(c[:-1, 0] * c[1:, 1] - c[1:, 0] * c[:-1, 1])
    winding = float(abs(swept) / (np.pi / 4 * span ** 2) / max(len(starts) - 1, 1))
    if len(starts) < 2:
        raise InputError(
            f"fewer than one full cycle in {len(t)} frames: the first embedding coordinate "
            f"rises through its median {len(starts)} time(s) (its range is {span:.3g}). "
            f"Record at least two cycles, or check the frames' times and the segmentation.")
    starts = np.array(starts)
    period = float(np.mean(np.diff(starts)))
    idx = np.searchsorted(starts, t, side="right") - 1
    phase = np.empty(len(t))
    inside = (idx >= 0) & (idx < len(starts) - 1)
    dur = np.diff(starts)
    phase[inside] = (t[inside] - starts[idx[inside]]) / dur[idx[inside]]
    before, after = idx < 0, idx >= len(starts) - 1
    phase[before] = 1.0 - (starts[0] - t[before]) / period
    phase[after] = (t[after] - starts[-1]) / period
    phase = np.mod(phase, 1.0)
    loop = winding > 0.1
    if loop:
        phase = _geometric_phase(y, t, starts, phase)
    out = np.empty_like(phase)
    out[order] = phase
    return Cycles(starts, period, out, winding, loop=loop)


def _geometric_phase(y, t, starts, time_phase, n_grid: int = 101):
    """Phases of a loop from the angle of the embedding about its centre (a function of the
    shape alone), mapped to time by the mean over the complete cycles of the time fraction
    reached at each angle: frames of cycles of unequal duration, or cut anywhere, get the
    phase of their shape (module doc)."""
    c = y[:, :2] - y[:, :2].mean(axis=0)
    psi = np.unwrap(np.arctan2(c[:, 1], c[:, 0]))
    psi *= np.sign(psi[-1] - psi[0]) or 1.0
    psi0 = np.interp(starts[0], t, psi)
    g = np.mod((psi - psi0) / (2 * np.pi), 1.0)
    grid = np.linspace(0.0, 1.0, n_grid)
    maps = []
    for a, b in zip(starts[:-1], starts[1:]):
        k = (t >= a) & (t < b)
        if k.sum() < 4:
            continue
        order = np.argsort(g[k])
        gg = np.concatenate([[0.0], g[k][order], [1.0]])
        ss = np.concatenate([[0.0], np.maximum.accumulate(time_phase[k][order]), [1.0]])
        maps.append(np.interp(grid, gg, ss))
    if not maps:
        return time_phase
    tau = np.maximum.accumulate(np.mean(maps, axis=0))
    return np.mod(np.interp(g, grid, tau), 1.0)


class PeriodicLME:
    """LME basis on ``n_bins`` periodic nodes of φ ∈ [0, 1) (module doc); ``approximant``:
    an unfitted approximant plugin instance (LME from the registry)."""

    def __init__(self, approximant, n_bins: int = 40):
        self.n = int(n_bins)
        base = np.arange(self.n) / self.n
        self.nodes = np.concatenate([base - 1.0, base, base + 1.0])[:, None]
        self.basis = approximant.fit(self.nodes)

    def matrices(self, phase):
        """(P, dP/dφ) as dense (m, n_bins) matrices at the phases."""
        b = self.basis.evaluate(np.mod(np.asarray(phase, float), 1.0)[:, None], order=1)
        N = 3 * self.n
        P = b.to_csr(N).toarray()
        D = b.gradient_csr(N, 0).toarray()
        fold = lambda M: M[:, :self.n] + M[:, self.n:2 * self.n] + M[:, 2 * self.n:]  # noqa
        return fold(P), fold(D)

    def fit(self, phase, values, ridge: float = 1e-10):
        """Nodal values (n_bins, D) of the least-squares fit to ``values`` (m, D) at ``phase``;
        InputError where a bin's basis has no frame near it."""
        P, _ = self.matrices(phase)
        cover = P.sum(axis=0)
        if (cover < 1e-3).any():
            empty = np.flatnonzero(cover < 1e-3) / self.n
            raise InputError(f"no frames near phase(s) {np.round(empty, 3).tolist()} of the "
                             f"stroke: lower the number of bins (study.n_bins) or give more "
                             f"frames.")
        A = P.T @ P + ridge * np.trace(P.T @ P) / self.n * np.eye(self.n)
        self.coefficients_ = np.linalg.solve(A, P.T @ values)
        return self.coefficients_

    def __call__(self, phase):
        """(X(φ), dX/dφ) (m, D) each, from the fitted nodal values."""
        P, D = self.matrices(phase)
        return P @ self.coefficients_, D @ self.coefficients_
