"""The eABF step of :class:`.eabf_grid.EABFGrid` as one numba kernel on arrays (a biased MD
step calls it once; the same operations in numpy on (d,)-arrays cost ~120 µs per step in
call overhead, as much as the SandCV evaluation itself).

Units as :mod:`.eabf_grid`: ξ, λ in the CV units [ξ_a]; k in kJ/mol/[ξ_a]²; mass in
kJ/mol ps²/[ξ_a]²; kT in kJ/mol; friction 1/ps; dt in ps. Periodic axes have a finite
``periods[a]`` (NaN otherwise); ``region`` holds facet rows (n, c) with n·λ + c ≤ 0 inside
(shape (0, d + 1) for none). The scheme (BAOAB on λ with the ABF bias ramped in per bin,
reflecting walls) is documented in :mod:`.eabf_grid` and :mod:`.eabf`.
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(cache=True)
def wrap1(d, p):
    """d folded into [−p/2, p/2) where p is a period; unchanged where p is NaN."""
    if math.isnan(p):
        return d
    return (d + 0.5 * p) % p - 0.5 * p


@nb.njit(cache=True)
def fold(v, lower, periods):
    """v with periodic axes brought into [lower, lower + period), in place."""
    for a in range(v.shape[0]):
        if not math.isnan(periods[a]):
            v[a] = lower[a] + (v[a] - lower[a]) % periods[a]


@nb.njit(cache=True)
def flat_bin(v, lower, width, n_bins, periods):
    """Flat (C-order) bin of a CV value v (d,), folded on periodic axes; −1 outside the box."""
    d = v.shape[0]
    b = 0
    for a in range(d):
        x = v[a]
        if not math.isnan(periods[a]):
            x = lower[a] + (x - lower[a]) % periods[a]
        i = int(math.floor((x - lower[a]) / width[a]))
        if i < 0 or i >= n_bins[a]:
            return -1
        b = b * n_bins[a] + i
    return b


@nb.njit(cache=True)
def coupling(f, xi, lam, k, periods):
    """f = k (ξ − λ) per axis (wrapped on periodic axes), in place."""
    for a in range(f.shape[0]):
        f[a] = k[a] * wrap1(xi[a] - lam[a], periods[a])


@nb.njit(cache=True)
def _kick(vel, f, b, f_sum, f_count, full_samples, mass, h):
    """vel += h (f + ABF bias of bin b) / m, the bias minus the running mean of F_λ in b ramped
    in by min(1, n / full_samples) (none outside the box or in an empty bin)."""
    n = f_count[b] if b >= 0 else 0
    ramp = min(1.0, n / full_samples) if n > 0 else 0.0
    for a in range(vel.shape[0]):
        ba = -ramp * f_sum[b, a] / n if n > 0 else 0.0
        vel[a] += h * (f[a] + ba) / mass[a]


@nb.njit(cache=True)
def drift(lam, vel, h, lower, upper, periods, region):
    """λ += h v, reflected at the box (non-periodic axes) and, if it leaves the convex region,
    undone with v reflected on the most violated facet; then folded."""
    d = lam.shape[0]
    old = lam.copy()
    for a in range(d):
        lam[a] = lam[a] + h * vel[a]
    for a in range(d):
        if not math.isnan(periods[a]):
            continue
        if lam[a] < lower[a]:
            lam[a], vel[a] = 2 * lower[a] - lam[a], -vel[a]
        elif lam[a] > upper[a]:
            lam[a], vel[a] = 2 * upper[a] - lam[a], -vel[a]
    worst, j = 0.0, -1
    for r in range(region.shape[0]):
        s = region[r, d]
        for a in range(d):
            s += region[r, a] * lam[a]
        if s > 0 and (j < 0 or s > worst):
            worst, j = s, r
    if j >= 0:
        vn = 0.0
        for a in range(d):
            vn += vel[a] * region[j, a]
        for a in range(d):
            lam[a] = old[a]
            vel[a] = vel[a] - 2 * vn * region[j, a]
    fold(lam, lower, periods)


@nb.njit(cache=True)
def eabf_step(lam, vel, xi, noise, dt, lower, upper, width, n_bins, periods, region, k, mass,
              kT, friction, full_samples, f_sum, f_count, z_count, z_lam_sum):
    """Accumulate F_λ = k (ξ − λ) in λ's bin and λ − ξ in ξ's bin, then one BAOAB step of λ
    (``noise``: d standard normal draws), in place on lam, vel and the accumulators."""
    d = lam.shape[0]
    f = np.empty(d)
    coupling(f, xi, lam, k, periods)
    bl = flat_bin(lam, lower, width, n_bins, periods)
    if bl >= 0:
        for a in range(d):
            f_sum[bl, a] += f[a]
        f_count[bl] += 1
    bz = flat_bin(xi, lower, width, n_bins, periods)
    if bz >= 0:
        z_count[bz] += 1
        for a in range(d):
            z_lam_sum[bz, a] += wrap1(lam[a] - xi[a], periods[a])
    _kick(vel, f, bl, f_sum, f_count, full_samples, mass, 0.5 * dt)
    drift(lam, vel, 0.5 * dt, lower, upper, periods, region)
    c = math.exp(-friction * dt)
    for a in range(d):
        vel[a] = c * vel[a] + math.sqrt((1 - c * c) * kT / mass[a]) * noise[a]
    drift(lam, vel, 0.5 * dt, lower, upper, periods, region)
    bl = flat_bin(lam, lower, width, n_bins, periods)
    coupling(f, xi, lam, k, periods)
    _kick(vel, f, bl, f_sum, f_count, full_samples, mass, 0.5 * dt)
