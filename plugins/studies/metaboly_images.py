"""From frames of an axisymmetric cell to its generating curves (stages 2–3 of the metaboly
pipeline, Arroyo, Heltai, Millán & DeSimone, PNAS 109 (2012) 17874).

Per frame (pixel coordinates x to the right, y down, pixel (i, j) centred at x = j, y = i):

1. :func:`flatten_background`: Gaussian smoothing, then division by a quadratic background
   fitted robustly to block medians (iteratively dropping blocks off the fit by > 3 MADs, so
   the cell does not bias it): uneven illumination becomes a flat relative contrast.
2. :func:`segment_details`: Otsu threshold of the flattened image; the cell's polarity is the
   side of the threshold away from the background mode (the median); the largest component,
   opened, closed and hole-filled. Refused with a reason: a blank frame, a contrast at the
   noise level, no component of plausible area, a component touching the image border.
3. :func:`subpixel_contour`: the closed iso-contour (marching squares) at the level midway
   between the background and cell medians (the edge of a symmetrically blurred step) that
   surrounds the component.
4. :func:`axisymmetric_profile`: the axis is the principal axis of the enclosed polygon
   (exact area moments); the two half-silhouettes r_left(z), r_right(z) are read where the
   contour crosses stations z = z_mid + h cos θ (θ uniform: dense at the poles) and averaged.
5. :func:`orient_consistently`: the axis has a 180° ambiguity. In time order, each frame's
   flip z → −z is chosen so that the profiles are best predicted by straight lines through
   their neighbours in time (an exact Viterbi pass): a stroke passing through a top–bottom
   symmetric shape is continued, not reflected back, which comparing consecutive frames
   alone cannot tell apart.
"""
from __future__ import annotations

from collections import Counter

import numpy as np
from scipy import ndimage

from pointatlas.errors import InputError

REASON_BLANK = "blank frame"
REASON_NOISE = "no distinct cell"
REASON_SIZE = "no component of plausible size"
REASON_BORDER = "cell touches the border"
REASON_CONTOUR = "no closed contour around the cell"
REASON_ASYMMETRIC = "asymmetric silhouette"


# -- 1. background ----------------------------------------------------------------------------

def flatten_background(frame: np.ndarray, smooth: float = 1.0, blocks: int = 32,
                       degree: int = 2) -> np.ndarray:
    """Smoothed ``frame`` (Gaussian σ = ``smooth`` px) divided by its fitted background, minus
    1: 0 on the background, the relative contrast elsewhere (a difference instead where the
    background nears 0, e.g. dark field). ``blocks``: blocks per side of the fit."""
    s = ndimage.gaussian_filter(np.asarray(frame, dtype=np.float64), smooth) if smooth > 0 \
        else np.asarray(frame, dtype=np.float64)
    H, W = s.shape
    b = max(1, min(H, W) // blocks)
    gh, gw = H // b, W // b
    med = np.median(s[:gh * b, :gw * b].reshape(gh, b, gw, b).transpose(0, 2, 1, 3)
                    .reshape(gh, gw, b * b), axis=2).ravel()
    cy, cx = np.meshgrid((np.arange(gh) + 0.5) * b - 0.5, (np.arange(gw) + 0.5) * b - 0.5,
                         indexing="ij")
    scale = max(H, W) / 2.0
    terms = [(i, d - i) for d in range(degree + 1) for i in range(d + 1)]
    bu, bv = (cx.ravel() - W / 2) / scale, (cy.ravel() - H / 2) / scale
    X = np.column_stack([bu ** i * bv ** j for i, j in terms])
    keep = np.ones(len(med), bool)
    for _ in range(8):
        coef = np.linalg.lstsq(X[keep], med[keep], rcond=None)[0]
        res = med - X @ coef
        mad = 1.4826 * np.median(np.abs(res[keep] - np.median(res[keep])))
        new = np.abs(res) <= 3.0 * max(mad, 1e-4 * max(abs(np.median(med)), 1e-3))
        if new.sum() < X.shape[1] * 3 or np.array_equal(new, keep):
            break
        keep = new
    u, v = (np.arange(W) - W / 2) / scale, (np.arange(H)[:, None] - H / 2) / scale
    background = sum(c * (u ** i * v ** j) for c, (i, j) in zip(coef, terms))
    if background.min() > 0.05 * max(abs(background).max(), 1e-12):
        return s / background - 1.0
    return s - background


# -- 2. segmentation ---------------------------------------------------------------------------

def _largest(binary: np.ndarray) -> np.ndarray:
    """The largest 4-connected component of ``binary`` (all False if none)."""
    labels, n = ndimage.label(binary)
    if n == 0:
        return np.zeros_like(binary)
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    return labels == int(np.argmax(sizes))


def segment_details(frame: np.ndarray, smooth: float = 1.0, min_area: float = 0.002,
                    max_area: float = 0.5, min_contrast: float = 4.0, radius: int = 2) -> dict:
    """Segmentation of one frame (module doc, step 2) with what was tried.

    ``min_area``/``max_area``: plausible cell area as fractions of the frame (and ≥ 50 px);
    ``min_contrast``: least (cell − background) / noise, both robust (medians, MAD);
    ``radius``: px of the opening/closing disc. Returns ``mask`` (bool (H, W) or None),
    ``reason`` ('' when found), ``signed`` (flattened image with the cell positive),
    ``threshold`` (Otsu, flattened units), ``polarity`` ('dark'/'bright' cell), ``level``
    (contour level in ``signed``), ``contrast`` (in noise units).
    """
    from skimage.filters import threshold_otsu

    flat = flatten_background(frame, smooth)
    out = {"mask": None, "reason": "", "signed": flat, "threshold": float("nan"),
           "polarity": "", "level": float("nan"), "contrast": 0.0}
    if np.ptp(flat) < 1e-9:
        out["reason"] = REASON_BLANK
        return out
    step = 2 if min(flat.shape) >= 128 else 1        # statistics on every other pixel
    sub = flat[::step, ::step]
    t = float(threshold_otsu(sub))
    median = float(np.median(sub))
    sign = -1.0 if t < median else 1.0
    signed, sub = sign * flat, sign * sub
    out.update(signed=signed, threshold=t, polarity="dark" if sign < 0 else "bright")
    noise = max(1.4826 * float(np.median(np.abs(sub - sign * median))), 1e-12)
    above = sub > sign * t
    if above.all() or not above.any():
        out["reason"] = REASON_BLANK
        return out
    cell, bg = float(np.median(sub[above])), float(np.median(sub[~above]))
    out["contrast"] = (cell - bg) / noise
    if out["contrast"] < min_contrast:
        out["reason"] = f"{REASON_NOISE}: contrast {out['contrast']:.1f}x the noise"
        return out
    comp = _largest(signed > sign * t)
    rows, cols = np.nonzero(comp)
    pad = 4 * radius + 4
    i0, i1 = max(rows.min() - pad, 0), min(rows.max() + pad + 1, flat.shape[0])
    j0, j1 = max(cols.min() - pad, 0), min(cols.max() + pad + 1, flat.shape[1])
    disc = np.hypot(*np.mgrid[-radius:radius + 1, -radius:radius + 1]) <= radius + 0.01
    crop = _largest(ndimage.binary_opening(comp[i0:i1, j0:j1], disc))
    crop = ndimage.binary_fill_holes(ndimage.binary_closing(crop, disc))
    area = int(crop.sum())
    lo, hi = max(50, min_area * flat.size), max_area * flat.size
    if not lo <= area <= hi:
        out["reason"] = f"{REASON_SIZE}: largest {area} px, expected {lo:.0f}-{hi:.0f} px"
        return out
    if comp[0].any() or comp[-1].any() or comp[:, 0].any() or comp[:, -1].any():
        out["reason"] = REASON_BORDER
        return out
    mask = np.zeros(flat.shape, bool)
    mask[i0:i1, j0:j1] = crop
    core = ndimage.binary_erosion(crop, disc, iterations=2)
    ring = np.zeros(flat.shape, bool)
    ring[i0:i1, j0:j1] = ndimage.binary_dilation(crop, disc, iterations=3)
    cell = float(np.median(signed[i0:i1, j0:j1][core])) if core.any() else cell
    bg = float(np.median(sub[~ring[::step, ::step]]))
    out.update(mask=mask, level=0.5 * (cell + bg))
    return out


def segment(frame: np.ndarray, **options) -> tuple[np.ndarray | None, str]:
    """(cell mask or None, the reason why none: '' if found); options: :func:`segment_details`."""
    found = segment_details(frame, **options)
    return found["mask"], found["reason"]


# -- 3. contour ----------------------------------------------------------------------------------

def subpixel_contour(image: np.ndarray, mask: np.ndarray, level: float,
                     polarity: str = "bright") -> np.ndarray | None:
    """Closed contour (m, 2), pixel (x, y), at ``level`` of ``image`` around ``mask``'s
    component (None if there is none); ``polarity``: whether the cell is above ('bright') or
    below ('dark') ``level``. Values away from the component (> 4 px) are ignored."""
    from skimage.measure import find_contours, points_in_poly

    img = np.asarray(image, dtype=np.float64)
    if polarity == "dark":
        img, level = -img, -level
    rows, cols = np.nonzero(mask)
    i0, i1 = max(rows.min() - 6, 0), min(rows.max() + 7, img.shape[0])
    j0, j1 = max(cols.min() - 6, 0), min(cols.max() + 7, img.shape[1])
    near = ndimage.binary_dilation(mask[i0:i1, j0:j1], iterations=4)
    low = min(level, float(img[i0:i1, j0:j1].min())) - 1.0
    crop = np.pad(np.where(near, img[i0:i1, j0:j1], low), 1, constant_values=low)
    dist = ndimage.distance_transform_edt(mask[i0:i1, j0:j1])
    ci, cj = np.unravel_index(np.argmax(dist), dist.shape)
    best, best_area = None, 0.0
    for c in find_contours(crop, level):
        if len(c) < 4 or np.hypot(*(c[0] - c[-1])) > 1e-6:
            continue
        xy = np.column_stack([c[:, 1] + j0 - 1, c[:, 0] + i0 - 1])
        area = 0.5 * abs(float(np.sum(xy[:, 0] * np.roll(xy[:, 1], -1)
                                      - np.roll(xy[:, 0], -1) * xy[:, 1])))
        if area > best_area and points_in_poly([[cj + j0, ci + i0]], xy)[0]:
            best, best_area = xy, area
    return best


# -- 4. profile -----------------------------------------------------------------------------------

def principal_axis(xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(centroid (2,), unit major axis (2,), area) of the region enclosed by the closed
    polygon ``xy`` from its exact area moments."""
    x, y = xy[:, 0], xy[:, 1]
    x2, y2 = np.roll(x, -1), np.roll(y, -1)
    c = x * y2 - x2 * y
    A = 0.5 * c.sum()
    cx, cy = ((x + x2) * c).sum() / (6 * A), ((y + y2) * c).sum() / (6 * A)
    ixx = ((x * x + x * x2 + x2 * x2) * c).sum() / (12 * A) - cx * cx
    iyy = ((y * y + y * y2 + y2 * y2) * c).sum() / (12 * A) - cy * cy
    ixy = ((x * y2 + 2 * x * y + 2 * x2 * y2 + x2 * y) * c).sum() / (24 * A) - cx * cy
    major = np.linalg.eigh(np.array([[ixx, ixy], [ixy, iyy]]))[1][:, 1]  # largest eigenvalue
    return np.array([cx, cy]), major, abs(A)


def _crossings(a, b, z):
    """Largest b > 0 and largest −b (b < 0) where the closed polyline (a, b) crosses a = z,
    for each station z (n,): two arrays (n,), 0 where there is no crossing."""
    a2, b2 = np.roll(a, -1), np.roll(b, -1)
    da = a2 - a
    hit = ((a[None] - z[:, None]) * (a2[None] - z[:, None]) <= 0) & (da[None] != 0)
    t = (z[:, None] - a[None]) / np.where(da == 0, 1.0, da)[None]
    bc = np.where(hit, b[None] + t * (b2 - b)[None], 0.0)
    return np.clip(bc, 0, None).max(axis=1), np.clip(-bc, 0, None).max(axis=1)


def axisymmetric_profile(contour_xy: np.ndarray, pixel_size: float, n: int = 101,
                         pole_px: float = 2.0) -> dict:
    """Generating curve of the silhouette bounded by ``contour_xy`` ((m, 2) px).

    Returns ``curve`` (n, 2) (r, z) µm from the top pole (z = +h, h the half-length) to the
    bottom pole, z measured from the midpoint between the poles along the axis;
    ``axis_angle`` (rad, image x/y, direction of the top pole), ``centre`` (x, y) px of the
    point z = 0 on the axis; ``asymmetry`` = max |r_left − r_right| / max r over the stations
    farther than ``pole_px`` pixels from the poles (at the tips the halves are sub-pixel
    slivers whose split follows the noise); ``halves`` (n, 2): (r_left, r_right) µm.
    """
    P = np.asarray(contour_xy, dtype=np.float64)
    c, u, _ = principal_axis(P)
    w = np.array([-u[1], u[0]])
    a, b = (P - c) @ u, (P - c) @ w
    top, bottom = float(a.max()), float(a.min())
    mid, h = 0.5 * (top + bottom), 0.5 * (top - bottom)
    z = mid + h * np.cos(np.linspace(0.0, np.pi, n))
    right, left = _crossings(a, b, z[1:-1])
    right, left = np.r_[0.0, right, 0.0], np.r_[0.0, left, 0.0]
    r = 0.5 * (left + right)
    rmax = max(float(r.max()), 1e-12)
    away = np.abs(np.abs(z - mid) - h) >= min(pole_px, 0.25 * h)
    return {"curve": np.column_stack([r, z - mid]) * pixel_size,
            "axis_angle": float(np.arctan2(u[1], u[0])), "centre": c + mid * u,
            "asymmetry": float(np.abs(left - right)[away].max() / rmax),
            "halves": np.column_stack([left, right]) * pixel_size}


# -- 5. orientation -------------------------------------------------------------------------------

def flip_curve(curve: np.ndarray) -> np.ndarray:
    """The curve with z → −z, still listed from the top pole."""
    return np.column_stack([curve[::-1, 0], -curve[::-1, 1]])


def _radius_vector(curve: np.ndarray, m: int) -> np.ndarray:
    """r at m stations of the normalized axis position, top pole to bottom pole."""
    r, z = curve[:, 0], curve[:, 1]
    zn = (z - 0.5 * (z.max() + z.min())) / max(0.5 * np.ptp(z), 1e-12)
    order = np.argsort(zn)
    return np.interp(np.linspace(1.0, -1.0, m), zn[order], r[order])


def _extrapolation_weights(t_hist: np.ndarray, t_new: float, tau: float) -> np.ndarray:
    """β (h,): the value at ``t_new`` of the straight line fitted to values at ``t_hist`` by
    least squares with weights exp(−|t_new − t|/τ) is Σ β_j value_j (the mean if h = 1
    or the times coincide)."""
    omega = np.exp(-np.abs(t_new - t_hist) / tau)
    X = np.column_stack([np.ones(len(t_hist)), t_hist - t_new])
    M = X.T @ (omega[:, None] * X)
    if len(t_hist) < 2 or np.linalg.det(M) <= 1e-12 * max(M[0, 0] * M[1, 1], 1e-300):
        return omega / omega.sum()
    return np.linalg.solve(M, X.T * omega)[0]


def orientation_flips(curves, times, window: int = 4, m: int = 64) -> np.ndarray:
    """Which curves to flip (bool (K,), input order) for a consistent orientation in time.

    A flip z → −z changes the sign of the antisymmetric part A = (r(ζ) − r(−ζ))/2 of a
    profile r(ζ) (ζ ∈ [−1, 1] the normalized axis position) and nothing else: the choice is of
    signs σ_k making σ_k A_k a smooth function of time: each σ_k A_k is predicted by the
    weighted straight-line fit of the ``window`` previous frames in time, and of the
    ``window`` next ones (weights exp(−Δt/τ), τ twice the median frame spacing); the sum of
    squared prediction residuals, each divided by its noise variance 1 + Σβ², is minimized
    exactly by a Viterbi pass over the signs of the last ``window`` frames. The earliest
    frame is not flipped. Needs ≳ 8 frames per stroke cycle: sparser, the direction in
    which a stroke passes through a top–bottom symmetric shape is not determined.
    """
    times, K = np.asarray(times, dtype=np.float64), len(curves)
    if K < 2:
        return np.zeros(K, bool)
    order = np.argsort(times, kind="stable")
    V = np.stack([_radius_vector(np.asarray(curves[k]), m) for k in order])
    A = 0.5 * (V - V[:, ::-1])
    t = times[order]
    steps = np.diff(t)
    tau = 2.0 * float(np.median(steps[steps > 0])) if np.any(steps > 0) else 1.0
    w = max(1, min(int(window), K - 1))
    n_states = 2 ** w
    states = np.arange(n_states)
    sign = 1.0 - 2.0 * ((states[:, None] >> np.arange(w)[None]) & 1)   # [state, i]: frame k-1-i
    cost = np.full(n_states, np.inf)
    cost[0] = 0.0                                                   # frame 0 kept: the gauge
    back = np.zeros((K, n_states), np.int8)
    for k in range(1, K):
        hist = k - 1 - np.arange(min(w, k))
        beta = _extrapolation_weights(t[hist], t[k], tau)
        pred = (sign[:, :len(hist)] * beta) @ A[hist]               # [state, m]
        res = np.stack([((A[k] - pred) ** 2).sum(-1), ((-A[k] - pred) ** 2).sum(-1)], axis=1)
        total = cost[:, None] + res / (1.0 + float(beta @ beta))     # [state, s]
        if k >= w:  # and frame k - w predicted back from frames k - w + 1 .. k
            later = k - np.arange(w)                                 # k, k-1, ..., k-w+1
            beta = _extrapolation_weights(t[later], t[k - w], tau)
            part = (sign[:, :w - 1] * beta[1:]) @ A[later[1:]]       # [state, m]
            back_pred = part[:, None] + beta[0] * np.array([1.0, -1.0])[None, :, None] * A[k]
            own = sign[:, w - 1][:, None, None] * A[k - w]
            total += ((own - back_pred) ** 2).sum(-1) / (1.0 + float(beta @ beta))
        older = [(states >> 1) | (b << (w - 1)) for b in (0, 1)]    # predecessors of a state
        options = np.stack([total[older[b], states & 1] for b in (0, 1)])
        back[k] = np.argmin(options, axis=0)
        cost = options.min(axis=0)
    state = int(np.argmin(cost))
    chosen = np.zeros(K, bool)
    for k in range(K - 1, 0, -1):
        chosen[k] = bool(state & 1)
        state = (state >> 1) | (int(back[k][state]) << (w - 1))
    flips = np.zeros(K, bool)
    flips[order] = chosen
    return flips


def orient_consistently(curves, times) -> tuple[list[np.ndarray], np.ndarray]:
    """(curves flipped where :func:`orientation_flips` says, in input order; the flips)."""
    flips = orientation_flips(curves, times)
    return [flip_curve(c) if f else np.asarray(c) for c, f in zip(curves, flips)], flips


# -- all frames -----------------------------------------------------------------------------------

def process_frames(seq, n_profile: int = 101, smooth: float = 1.0, max_asymmetry=None,
                   **options) -> dict:
    """Generating curves of the frames of a :class:`FrameSequence` ``seq`` (module doc).

    Returns ``kept`` (K,) bool and ``reason`` (K,) str in the sequence's frame order (''
    for kept frames), ``asymmetry``, ``axis_angle`` (rad, after orientation), ``centre``
    (K, 2) px, ``threshold`` and ``polarity`` (NaN/'' where not computed); for the kept
    frames in time order: ``index`` (into the sequence), ``times`` (s), ``curves``
    (n_kept, n_profile, 2) (r, z) µm, consistently oriented, ``flipped``; ``counts``:
    frames, kept, dropped and dropped by reason (the part before a colon: ``REASON_*``).
    ``max_asymmetry``: drop frames whose asymmetry is above it (None: report only).
    ``options`` go to :func:`segment_details`. InputError if most frames show no cell.
    """
    K = seq.n_frames
    reason = [""] * K
    asym, angle = np.full(K, np.nan), np.full(K, np.nan)
    centre, thresh = np.full((K, 2), np.nan), np.full(K, np.nan)
    polarity, curves = [""] * K, {}
    for k in range(K):
        found = segment_details(seq.frames[k], smooth=smooth, **options)
        thresh[k], polarity[k] = found["threshold"], found["polarity"]
        if found["mask"] is None:
            reason[k] = found["reason"]
            continue
        xy = subpixel_contour(found["signed"], found["mask"], found["level"])
        if xy is None:
            reason[k] = REASON_CONTOUR
            continue
        prof = axisymmetric_profile(xy, seq.pixel_size, n_profile)
        asym[k], angle[k], centre[k] = prof["asymmetry"], prof["axis_angle"], prof["centre"]
        if max_asymmetry is not None and prof["asymmetry"] > max_asymmetry:
            reason[k] = f"{REASON_ASYMMETRIC}: {prof['asymmetry']:.2f} > {max_asymmetry}"
            continue
        curves[k] = prof["curve"]
    kept = np.array([not r for r in reason])
    no_cell = [r for r in reason if r and not r.startswith(REASON_ASYMMETRIC)]
    if len(no_cell) > 0.5 * K:
        common = Counter(r.split(":")[0] for r in no_cell).most_common(1)[0][0]
        pol = Counter(p for p in polarity if p).most_common(1)
        raise InputError(
            f"{seq.name}: {len(no_cell)} of {K} frames show no cell (mostly: {common}); tried "
            f"Otsu thresholds around {np.nanmedian(thresh):.3g} (relative contrast after "
            f"background flattening) with a {pol[0][0] if pol else 'undecided'} cell. Check "
            "the contrast of the cell against the background and pixel_size, or give a "
            "video cropped around one whole cell.")
    index = np.flatnonzero(kept)
    index = index[np.argsort(seq.times[index], kind="stable")]
    oriented, flips = orient_consistently([curves[k] for k in index], seq.times[index])
    angle[index[flips]] = np.angle(np.exp(1j * (angle[index[flips]] + np.pi)))
    dropped = Counter(r.split(":")[0] for r in reason if r)
    return {"kept": kept, "reason": reason, "asymmetry": asym, "axis_angle": angle,
            "centre": centre, "threshold": thresh, "polarity": polarity, "index": index,
            "times": seq.times[index], "flipped": flips,
            "curves": np.stack(oriented) if len(oriented) else np.empty((0, n_profile, 2)),
            "counts": {"frames": K, "kept": int(kept.sum()), "dropped": int(K - kept.sum()),
                       "by_reason": dict(dropped)}}


__all__ = ["flatten_background", "segment", "segment_details", "subpixel_contour",
           "principal_axis", "axisymmetric_profile", "flip_curve", "orientation_flips",
           "orient_consistently", "process_frames"]
