"""Pellicle kinematics of euglenid metaboly (Arroyo, Heltai, Millán & DeSimone, PNAS 109
(2012) 17874, SI "Pellicle kinematics", Eqs. S1–S9).

An axisymmetric cell is given by its generating curves c(u, t) = (r, z) (µm) at K phases
t_k = kT/K of one period T (s), top pole first, both poles on the axis (r = 0).

* Body coordinate (S1): λ(u, t) = (1/S(t)) ∫_0^u 2π r a dv, a = |∂c/∂u|, S(t) the area. If
  the (inextensible) pellicle preserves area, λ labels material parallels; every curve is
  resampled at the same λ nodes.
* Reference pellicle (S2, S9): r₀(λ) = min_t r(λ, t); dz₀/dλ = −√((S̄/2πr₀)² − r₀′²), S̄
  the mean area (′ = ∂/∂λ). Where the root's argument is negative the reference is not
  realisable: dz₀/dλ is set to 0 there and a warning says where.
* Shear (S6/S7): γ = (−cos α₀ + √((r/r₀)² − sin²α₀))/sin α₀, i.e. √((r/r₀)² − 1) for strips
  along the meridians (α₀ = π/2, the canonical choice).
* Azimuthal displacement (S5/S8): ψ′ = (r₀a₀/r²)[γ + cot α₀ (1 − (r/r₀)²)], a₀ = |∂c₀/∂λ|,
  integrated in λ with ∫_Γ ψ r dS = 0.
* Compatibility (S4): (a² + r²ψ′²)/a₀² = 1 − 2γ sin α₀ cos α₀ + γ² cos²α₀; its residual is a
  diagnostic (exactly zero for an area-preserving motion).
* Velocities at fixed λ (body frame): (∂r/∂t, ∂z/∂t, r ∂ψ/∂t).

Numerics. Instead of λ the module works in the Archimedes angle φ = arccos(1 − 2λ) ∈ [0, π]
(λ = (1 − cos φ)/2, exact for a sphere): r, z are smooth in φ near the poles (r ~ φ) where
they are not in λ (r ~ √λ). The material nodes are uniform in φ, so λ_j = (1 − cos φ_j)/2;
λ-derivatives are φ-derivatives times dφ/dλ = 2/sin φ, which cancels in every ratio used. At
the poles the ratios 0/0 take their limits: at a smooth pole λ ≈ πr²/S, so (∂r/∂φ)² = S/4π
and r/r₀ → √(S/S_min), sin φ / r₀ → 1/|∂r₀/∂φ|; ψ′ there is extrapolated from the three
nearest nodes. S9 is evaluated as (S̄/2πr₀)² − r₀′² = z′² + ((S̄² − S²)/(2πr₀)²) on the
minimising curve (S1 gives r′² + z′² = (S/2πr₀)²), free of cancellation near the poles. An
area-preserving motion has r/r₀ → 1, γ → 0 at the poles; if the area changes, γ does not
vanish there, ψ′ ~ 1/φ and ψ near the poles depends on the grid (a warning says so;
v_θ = rψ̇ → 0 stays finite). The pole limits assume a smooth pole (no conical tip). With
α₀ = π/2 the + root γ ≥ 0 has a kink in time where r touches r₀, so v_θ from the spectral
derivative of ψ converges slowly there.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import cumulative_simpson, simpson
from scipy.interpolate import CubicSpline

from pointatlas.errors import InputError

_GX, _GW = np.polynomial.legendre.leggauss(6)
_POLE_TOL = 1e-6            # |r| at a pole, relative to the curve's size
_NEG_TOL = 1e-9             # S9 argument below −tol·(S̄/2πr₀)² counts as not realisable
_POLE_SHEAR_WARN = 1e-2


@dataclass
class PellicleKinematics:
    lam: np.ndarray          # (m,) body coordinate nodes in [0, 1]
    positions: np.ndarray    # (K, m, 2) (r, z) µm
    velocities: np.ndarray   # (K, m, 3) (v_r, v_z, v_θ) µm/s
    shear: np.ndarray        # (K, m) γ
    psi: np.ndarray          # (K, m) azimuthal displacement (rad)
    r0: np.ndarray           # (m,) reference pellicle radius µm
    z0: np.ndarray           # (m,) reference pellicle height µm
    area: np.ndarray         # (K,) S(t) µm²
    area_deviation: float    # max |S − S̄| / S̄
    compatibility: float     # max |S4 residual| / a₀²
    not_realisable: int = 0  # nodes where the S9 root's argument is negative
    warnings: list[str] = field(default_factory=list)

    @property
    def shear_max(self) -> float:
        return float(np.max(self.shear))


# ---------------------------------------------------------------- one curve, body coordinate

def _check_curve(curve, name="curve") -> np.ndarray:
    c = np.array(curve, dtype=float)
    if c.ndim != 2 or c.shape[1] != 2 or len(c) < 5:
        raise InputError(f"{name} has shape {c.shape}: give (n, 2) nodes (r, z), n ≥ 5.")
    if not np.all(np.isfinite(c)):
        raise InputError(f"{name} has NaN/inf coordinates: give finite (r, z) nodes.")
    scale = np.max(np.abs(c))
    if abs(c[0, 0]) > _POLE_TOL * scale or abs(c[-1, 0]) > _POLE_TOL * scale:
        raise InputError(f"{name} starts at r = {c[0, 0]:.3g} and ends at r = {c[-1, 0]:.3g}: "
                         "the generating curve must run from pole to pole on the axis (r = 0).")
    c[[0, -1], 0] = 0.0
    bad = np.flatnonzero(c[1:-1, 0] <= 0.0)
    if bad.size:
        raise InputError(f"{name} touches or crosses the axis at node {bad[0] + 1}: "
                         "give r > 0 between the poles.")
    if c[0, 1] <= c[-1, 1]:
        raise InputError(f"{name} runs from z = {c[0, 1]:.3g} up to z = {c[-1, 1]:.3g}: "
                         "put the top pole first (reverse the node order).")
    if np.any(np.hypot(*np.diff(c, axis=0).T) <= 0.0):
        raise InputError(f"{name} has repeated nodes: remove the duplicates.")
    return c


def _splines(c):
    """Cubic splines r(s), z(s) in chord length s (µm), with the pole symmetry (r odd: r'' = 0;
    z even: z' = 0) as end conditions."""
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(c, axis=0).T))])
    sr = CubicSpline(s, c[:, 0], bc_type="natural")
    sz = CubicSpline(s, c[:, 1], bc_type=((1, 0.0), (1, 0.0)))
    return s, sr, sz


def _interval_integrals(s, integrand):
    """∫ integrand ds over each interval [s_i, s_{i+1}] by 6-point Gauss–Legendre."""
    h = np.diff(s)
    x = s[:-1, None] + 0.5 * h[:, None] * (_GX[None, :] + 1.0)
    return 0.5 * h * (integrand(x) @ _GW)


def _ring_area_rate(sr, sz):
    """dS/ds = 2π r |c_s| (µm): the area of the surface of revolution per unit s."""
    return lambda x: 2 * np.pi * sr(x) * np.hypot(sr(x, 1), sz(x, 1))


def _areas(s, sr, sz):
    """Areas (µm²) from the top pole to each node, from the bottom pole, and the total S."""
    d = _interval_integrals(s, _ring_area_rate(sr, sz))
    top = np.concatenate([[0.0], np.cumsum(d)])
    bottom = np.concatenate([np.cumsum(d[::-1])[::-1], [0.0]])
    return top, bottom, top[-1]


def _angle(top, bottom, area):
    """φ = arccos(1 − 2λ) from the areas on either side (no cancellation near the poles)."""
    lo = 2 * np.arcsin(np.sqrt(np.clip(top / area, 0, 1)))
    hi = np.pi - 2 * np.arcsin(np.sqrt(np.clip(bottom / area, 0, 1)))
    return np.where(top <= bottom, lo, hi)


def body_coordinate(curve) -> np.ndarray:
    """λ (Eq. S1) at the nodes of one generating curve (n, 2) = (r, z) µm: the fraction of the
    surface area between the top pole and each node, 0 at the top pole, 1 at the bottom."""
    c = _check_curve(curve)
    top, bottom, area = _areas(*_splines(c))
    return np.where(top <= bottom, top / area, 1.0 - bottom / area)


def _resample(c, phi, dc=None):
    """r, z, ∂r/∂φ, ∂z/∂φ at the material angles φ, the area S, and (if ``dc``, the rates
    ∂c/∂t at fixed node) the rates at fixed λ: ∂c/∂t|_λ = ∂c/∂t|_u − e_u Q/(2πr),
    Q = Ȧ|_u − λ Ṡ (Ȧ the rate of the area above u, e_u the unit tangent)."""
    s, sr, sz = _splines(c)
    top, bottom, area = _areas(s, sr, sz)
    phi_nodes = _angle(top, bottom, area)
    if np.any(np.diff(phi_nodes) <= 0):
        raise InputError("a curve has zero-area segments: give distinct nodes with r > 0.")
    s_of = CubicSpline(phi_nodes, s, bc_type="natural")
    sj, ds = s_of(phi), s_of(phi, 1)
    r, z = sr(sj), sz(sj)
    r[[0, -1]] = 0.0
    out = [r, z, sr(sj, 1) * ds, sz(sj, 1) * ds, area]
    if dc is not None:
        vr = CubicSpline(s, dc[:, 0], bc_type="natural")
        vz = CubicSpline(s, dc[:, 1], bc_type=((1, 0.0), (1, 0.0)))

        def rate(x):          # ∂/∂t of 2π r |c_s| at fixed s
            rs, zs = sr(x, 1), sz(x, 1)
            a = np.hypot(rs, zs)
            return 2 * np.pi * (vr(x) * a + sr(x) * (rs * vr(x, 1) + zs * vz(x, 1)) / a)

        d = _interval_integrals(s, rate)
        adot = np.concatenate([[0.0], np.cumsum(d)])
        lam_nodes = (1 - np.cos(phi_nodes)) / 2
        q = CubicSpline(phi_nodes, adot - lam_nodes * adot[-1],      # Q even at the poles
                        bc_type=((1, 0.0), (1, 0.0)))(phi)
        rs, zs = sr(sj, 1), sz(sj, 1)
        a = np.hypot(rs, zs)
        coef = np.zeros_like(r)
        coef[1:-1] = -q[1:-1] / (2 * np.pi * r[1:-1] * a[1:-1])
        out.append(np.column_stack([vr(sj) + coef * rs, vz(sj) + coef * zs]))
    return out


# ---------------------------------------------------------------- helpers on the φ grid

def _spectral_dt(f, period):
    """∂f/∂t of samples f[k] at t = kT/K of a periodic function (FFT; Nyquist mode dropped)."""
    k = f.shape[0]
    w = 2j * np.pi * np.fft.fftfreq(k, d=period / k)
    if k % 2 == 0:
        w[k // 2] = 0.0
    fh = np.fft.fft(f, axis=0)
    return np.real(np.fft.ifft(fh * w.reshape((-1,) + (1,) * (f.ndim - 1)), axis=0))


def _cumulative(f, h):
    """Cumulative Simpson integral along the last axis (uniform step h), starting at 0."""
    return cumulative_simpson(f, dx=h, axis=-1, initial=0.0)


def shear(rho, alpha0=np.pi / 2):
    """Pellicle shear γ (Eq. S7, the + root) for the stretch ratio ρ = r/r₀ ≥ |sin α₀|."""
    s, c = _sin_cos(alpha0)
    return np.maximum((-c + np.sqrt(np.maximum(rho**2 - s**2, 0.0))) / s, 0.0)


def _sin_cos(alpha0):
    if np.isclose(alpha0, np.pi / 2, rtol=0, atol=1e-14):
        return 1.0, 0.0
    return np.sin(alpha0), np.cos(alpha0)


def _check_input(shapes, period, m, alpha0, dshapes, max_area_deviation):
    x = np.asarray(shapes, dtype=float)
    if x.ndim != 3 or x.shape[2] != 2:
        raise InputError(f"shapes have shape {x.shape}: give (K, n, 2) curves (r, z), "
                         "the same n nodes in each.")
    if x.shape[0] < 3:
        raise InputError(f"{x.shape[0]} phases: give at least 3 curves sampled uniformly "
                         "over one period (no repeated last sample).")
    if not (np.isfinite(period) and period > 0):
        raise InputError(f"period = {period}: give the stroke period T > 0 in seconds.")
    if int(m) != m or m < 7:
        raise InputError(f"m = {m}: give at least 7 material nodes (e.g. m=201).")
    if not (0 < alpha0 <= np.pi / 2 + 1e-14):
        raise InputError(f"alpha0 = {alpha0}: the strip angle must lie in (0, π/2].")
    if max_area_deviation is not None and not max_area_deviation >= 0:
        raise InputError(f"max_area_deviation = {max_area_deviation}: give a fraction ≥ 0 "
                         "(or None to accept any area change).")
    curves = np.stack([_check_curve(c, f"curve {k}") for k, c in enumerate(x)])
    if dshapes is not None:
        dshapes = np.asarray(dshapes, dtype=float)
        if dshapes.shape != x.shape or not np.all(np.isfinite(dshapes)):
            raise InputError(f"dshapes have shape {dshapes.shape}: give finite ∂(r, z)/∂t "
                             f"at the nodes, shape {x.shape} like shapes.")
    return curves, dshapes


# ---------------------------------------------------------------- the kinematics

def pellicle_kinematics(shapes, period, m=201, alpha0=np.pi / 2, dshapes=None,
                        max_area_deviation=0.05) -> PellicleKinematics:
    """Material (Lagrangian) description of the pellicle along a periodic stroke.

    shapes: (K, n, 2) generating curves (r, z) µm at t = kT/K, top pole first, r = 0 at the
    poles, any parametrisation. period: T (s). m: material nodes, uniform in φ = arccos(1−2λ)
    with both poles. alpha0: strip angle with the parallels in the reference (π/2: along the
    meridians). dshapes: optional (K, n, 2) ∂(r, z)/∂t at fixed node (µm/s); without it
    ∂(r, z)/∂t at fixed λ are spectral derivatives in phase. ∂ψ/∂t is spectral in both cases.
    max_area_deviation: largest accepted max|S − S̄|/S̄ (None: any).
    """
    curves, dshapes = _check_input(shapes, period, m, alpha0, dshapes, max_area_deviation)
    K, m = len(curves), int(m)
    phi = np.linspace(0.0, np.pi, m)
    h = phi[1] - phi[0]
    lam = (1 - np.cos(phi)) / 2
    lam[[0, -1]] = 0.0, 1.0
    res = [_resample(c, phi, None if dshapes is None else dshapes[k])
           for k, c in enumerate(curves)]
    r, z, r_p, z_p = (np.array([q[i] for q in res]) for i in range(4))
    area = np.array([q[4] for q in res])
    # smooth pole: λ ≈ πr²/S there (S1), so (∂r/∂φ)² = S/4π exactly
    r_p[:, 0], r_p[:, -1] = np.sqrt(area / (4 * np.pi)), -np.sqrt(area / (4 * np.pi))
    s_bar = area.mean()
    deviation = float(np.max(np.abs(area - s_bar)) / s_bar)
    if max_area_deviation is not None and deviation > max_area_deviation:
        raise InputError(f"the area varies by {100 * deviation:.2f} % over the stroke (limit "
                         f"{100 * max_area_deviation:.2g} %), so λ is not material: pass "
                         "max_area_deviation=<larger fraction> (or None) to accept it.")
    warns = []

    # reference pellicle (S9): r₀ = min_t r, r₀′ from the minimising curve k* (envelope).
    # With F = S̄/(2πr₀)·dλ/dφ and, for curve k*, r_φ² + z_φ² = F_k² (S1, S = S_k*), the
    # root's argument F² − r₀_φ² = z_φ² + F² − F_k²: no cancellation near the poles.
    kmin = np.argmin(r, axis=0)
    kmin[[0, -1]] = np.argmin(np.abs(r_p[:, [0, -1]]), axis=0)
    cols = np.arange(m)
    r0, r0_p, zk_p = r[kmin, cols], r_p[kmin, cols], z_p[kmin, cols]
    sin_over_r0 = np.empty(m)
    sin_over_r0[1:-1] = np.sin(phi[1:-1]) / r0[1:-1]
    sin_over_r0[[0, -1]] = 1.0 / np.abs(r0_p[[0, -1]])
    f = s_bar * sin_over_r0 / (4 * np.pi)
    arg = zk_p**2 + (s_bar**2 - area[kmin] ** 2) * (sin_over_r0 / (4 * np.pi)) ** 2
    bad = arg < -_NEG_TOL * f**2
    z0_p = -np.sqrt(np.maximum(arg, 0.0))
    a0_p = np.hypot(r0_p, z0_p)
    z0 = z[:, 0].mean() + _cumulative(z0_p, h)
    if bad.any():
        where = lam[bad]
        warns.append(f"reference pellicle not realisable at {bad.sum()} of {m} nodes "
                     f"(λ in [{where.min():.3f}, {where.max():.3f}]): (S̄/2πr₀)² < r₀′² "
                     "there, dz₀/dλ clipped to 0 (the area is not preserved).")

    # shear (S7) with the pole limit r/r₀ → (∂r/∂φ)/(∂r₀/∂φ) = √(S/S_min)
    rho = np.empty_like(r)
    rho[:, 1:-1] = r[:, 1:-1] / r0[1:-1]
    rho[:, [0, -1]] = np.sqrt(area / area.min())[:, None]   # ∂r/∂φ ÷ ∂r₀/∂φ
    gamma = shear(rho, alpha0)
    s, c = _sin_cos(alpha0)
    bracket = gamma + (c / s) * (1.0 - rho**2)        # r²ψ′/(r₀a₀), Eq. S8
    pole_gamma = float(np.max(gamma[:, [0, -1]]))
    if pole_gamma > _POLE_SHEAR_WARN:
        warns.append(f"γ does not vanish at the poles (up to {pole_gamma:.3g}) because the "
                     "area changes: ψ′ ~ 1/φ there, so ψ near the poles depends on the grid "
                     "(v_θ = rψ̇ → 0 stays finite).")

    # azimuthal displacement (S5/S8): ψ_φ = r₀ a₀_φ [..]/r², poles extrapolated
    psi_p = np.empty_like(r)
    psi_p[:, 1:-1] = r0[1:-1] * a0_p[1:-1] * bracket[:, 1:-1] / r[:, 1:-1] ** 2
    psi_p[:, 0] = 3 * psi_p[:, 1] - 3 * psi_p[:, 2] + psi_p[:, 3]
    psi_p[:, -1] = 3 * psi_p[:, -2] - 3 * psi_p[:, -3] + psi_p[:, -4]
    psi = _cumulative(psi_p, h)
    w = np.sin(phi) * r                                # ∝ r dS/dφ on Γ(t)
    psi -= (simpson(w * psi, dx=h, axis=1) / simpson(w, dx=h, axis=1))[:, None]

    # compatibility (S4), everything in φ (the factor (dλ/dφ)² cancels)
    a_p2 = r_p**2 + z_p**2
    rpsi2 = (a0_p * bracket / rho) ** 2               # r² ψ_φ²
    target = a0_p**2 * (1 - 2 * gamma * s * c + gamma**2 * c**2)
    compat = float(np.max(np.abs(a_p2 + rpsi2 - target) / a0_p**2))

    # velocities at fixed λ (body frame)
    vel = np.empty((K, m, 3))
    if dshapes is None:
        vel[..., 0] = _spectral_dt(r, period)
        vel[..., 1] = _spectral_dt(z, period)
    else:
        vel[..., :2] = np.array([q[5] for q in res])
    vel[:, [0, -1], 0] = 0.0
    vel[..., 2] = r * _spectral_dt(psi, period)
    return PellicleKinematics(
        lam=lam, positions=np.stack([r, z], axis=-1), velocities=vel, shear=gamma, psi=psi,
        r0=r0, z0=z0, area=area, area_deviation=deviation, compatibility=compat,
        not_realisable=int(bad.sum()), warnings=warns)
