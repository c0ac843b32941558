"""Tests of pointatlas_studies.pellicle (Arroyo et al., PNAS 2012, SI Eqs. S1–S9).

The main check is an analytic area-preserving stroke built here, independently of the module:
in the Archimedes angle φ (λ = (1 − cos φ)/2) the radius r(φ, t) is prescribed and z(φ, t)
follows from 2π r |∂c/∂λ| = S (so λ is exactly material), by Gauss quadrature of
∂z/∂φ = −√((S sin φ/4πr)² − (∂r/∂φ)²). The curves are handed to the module at a non-uniform,
time-dependent parametrisation; γ, ψ (S5 integrated on a fine grid with Simpson's rule, in a
pole-safe closed form) and the velocities (finite differences in t) are computed here.
"""
import numpy as np
import pytest
from scipy.integrate import cumulative_simpson, simpson

from pointatlas.errors import InputError
from pointatlas_studies.pellicle import body_coordinate, pellicle_kinematics

R, EPS, T = 5.0, 0.1, 2.0          # µm, modulation, s
S = 4 * np.pi * R**2
GX, GW = np.polynomial.legendre.leggauss(10)


def h(phi, t):
    return 0.5 * (1 + np.cos(2 * np.pi * t / T - 2 * phi))


def r_exact(phi, t):
    return R * np.sin(phi) * (1 + EPS * np.sin(phi) ** 2 * h(phi, t))


def r_dt(phi, t):
    return R * EPS * np.sin(phi) ** 3 * (-np.pi / T) * np.sin(2 * np.pi * t / T - 2 * phi)


def z_phi(phi, t):
    s, c = np.sin(phi), np.cos(phi)
    g = 1 + EPS * s**2 * h(phi, t)
    h_p = np.sin(2 * np.pi * t / T - 2 * phi)                     # ∂h/∂φ
    r_p = R * (c * g + s * EPS * (2 * s * c * h(phi, t) + s**2 * h_p))
    arg = (S / (4 * np.pi * R * g)) ** 2 - r_p**2        # sin φ / r = 1/(R g)
    assert arg.min() > -1e-12, "the test stroke is not realisable"
    return -np.sqrt(np.maximum(arg, 0.0))


def z_exact(phi, t):
    """z at sorted angles φ (from φ = 0) by 10-point Gauss–Legendre per interval."""
    edges = np.concatenate([[0.0], phi])
    a, b = edges[:-1, None], edges[1:, None]
    x = 0.5 * (a + b) + 0.5 * (b - a) * GX
    inc = 0.5 * (b[:, 0] - a[:, 0]) * (z_phi(x, t) @ GW)
    return R + 0.3 * np.sin(2 * np.pi * t / T) + np.cumsum(inc)


def node_angles(t, n=161):
    u = np.linspace(0, 1, n)
    return np.pi * (u + 0.04 * np.sin(2 * np.pi * u) * np.cos(2 * np.pi * t / T))


def curve(t, n=161):
    phi = node_angles(t, n)
    c = np.column_stack([r_exact(phi, t), z_exact(phi, t)])
    c[[0, -1], 0] = 0.0
    return c


def stroke(K):
    times = np.arange(K) * T / K
    return times, np.array([curve(t) for t in times])


def expected_psi(phi_fine, t, hmin, alpha0):
    """ψ from S5 with r₀a₀ = S sin φ/4π (the reference is realisable), pole-safe."""
    s2 = np.sin(phi_fine) ** 2
    g, g0 = 1 + EPS * s2 * h(phi_fine, t), 1 + EPS * s2 * hmin
    rho = g / g0
    q = EPS * (h(phi_fine, t) - hmin) * (rho + 1) / g0          # (ρ² − 1)/sin²φ
    if alpha0 == np.pi / 2:     # γ = √(ρ² − 1) = sin φ √q; S5: r²ψ′/(r₀a₀) = γ
        b_s = np.sqrt(q)
    else:                       # γ/sin²φ from the rationalised root of S6, then S5
        sa, ca = np.sin(alpha0), np.cos(alpha0)
        gam_s2 = q / (sa * ca + np.sqrt(sa**2 * ca**2 + sa**2 * q * s2))
        b_s = np.sin(phi_fine) * gam_s2 * ((sa**2 - ca**2) - gam_s2 * s2 * sa * ca)
    # ψ_φ = (r²ψ′/(r₀a₀)) · S sin φ/(4π r²), r = R sin φ g; b_s = that bracket / sin φ
    psi_p = b_s * S / (4 * np.pi * R**2 * g**2)
    psi = cumulative_simpson(psi_p, x=phi_fine, initial=0.0)
    w = r_exact(phi_fine, t) * np.sin(phi_fine)
    return psi - simpson(psi * w, x=phi_fine) / simpson(w, x=phi_fine)


def hmin_on(phi, analytic):
    """min over the sampled phases of h: the reference r₀ = min_t r at angles φ."""
    return np.min([h(phi, t) for t in analytic["times"]], axis=0)


@pytest.fixture(scope="module")
def analytic():
    K, m = 32, 201
    times, shapes = stroke(K)
    phi = np.linspace(0, np.pi, m)
    hmin = np.min([h(phi, t) for t in times], axis=0)
    return dict(K=K, m=m, times=times, shapes=shapes, phi=phi, hmin=hmin,
                pk=pellicle_kinematics(shapes, T, m=m))


def test_sphere_body_coordinate_is_archimedes():
    u = np.linspace(0, 1, 301)
    theta = np.pi * (3 * u**2 - 2 * u**3)            # non-uniform nodes
    c = np.column_stack([2.0 * np.sin(theta), 2.0 * np.cos(theta)])
    c[[0, -1], 0] = 0.0
    lam = body_coordinate(c)
    assert np.max(np.abs(lam - (1 - np.cos(theta)) / 2)) < 1e-7


def test_rigid_stroke_has_no_shear_nor_motion():
    th = np.linspace(0, np.pi, 201)
    c = np.column_stack([3.0 * np.sin(th), 6.0 * np.cos(th)])
    c[[0, -1], 0] = 0.0
    pk = pellicle_kinematics(np.repeat(c[None], 5, axis=0), 4.0, m=101)
    assert np.max(pk.shear) < 1e-6 and np.max(np.abs(pk.psi)) < 1e-6
    assert np.max(np.abs(pk.velocities)) < 1e-9
    assert pk.area_deviation < 1e-14 and pk.compatibility < 1e-5 and not pk.warnings
    # the reference is the shape itself: z₀ from S9 agrees with the spheroid at the nodes
    assert np.max(np.abs(pk.z0 - pk.positions[0, :, 1])) < 1e-3
    assert np.max(np.abs(pk.r0 - pk.positions[0, :, 0])) < 1e-12


def test_analytic_stroke_positions_are_material(analytic):
    pk, phi = analytic["pk"], analytic["phi"]
    assert np.allclose(pk.lam, (1 - np.cos(phi)) / 2, atol=1e-15)
    for k in (0, 7, 19):
        t = analytic["times"][k]
        assert np.max(np.abs(pk.positions[k, :, 0] - r_exact(phi, t))) < 1e-6
        assert np.max(np.abs(pk.positions[k, :, 1] - z_exact(phi, t))) < 1e-6
    assert abs(pk.area.mean() - S) / S < 1e-8 and pk.area_deviation < 1e-8


def test_analytic_stroke_shear_and_psi(analytic):
    pk, phi, hmin = analytic["pk"], analytic["phi"], analytic["hmin"]
    s2 = np.sin(phi) ** 2
    rho2 = ((1 + EPS * s2 * h(phi, analytic["times"][:, None]))
            / (1 + EPS * s2 * hmin)) ** 2
    err = np.abs(pk.shear - np.sqrt(rho2 - 1))
    assert np.max(err[:, 5:-5]) < 1e-5 and np.max(err) < 1e-4   # γ ~ √(ρ − 1) near the poles
    assert pk.shear_max > 0.1
    fine = np.linspace(0, np.pi, 50 * (analytic["m"] - 1) + 1)
    for k in (0, 5, 21):
        psi = expected_psi(fine, analytic["times"][k], hmin_on(fine, analytic), np.pi / 2)
        assert np.max(np.abs(pk.psi[k] - psi[::50])) < 2e-3 * np.max(np.abs(psi))
    assert pk.compatibility < 1e-4
    assert pk.not_realisable == 0 and not pk.warnings


def test_general_strip_angle(analytic):
    alpha0 = np.pi / 3
    phi, hmin, times = analytic["phi"], analytic["hmin"], analytic["times"]
    pk = pellicle_kinematics(analytic["shapes"], T, m=analytic["m"], alpha0=alpha0)
    s2 = np.sin(phi) ** 2
    rho2 = ((1 + EPS * s2 * h(phi, times[:, None])) / (1 + EPS * s2 * hmin)) ** 2
    g, sa, ca = pk.shear, np.sin(alpha0), np.cos(alpha0)
    assert np.max(np.abs(1 + 2 * g * sa * ca + g**2 * sa**2 - rho2)) < 1e-5      # S6
    assert np.all(g >= 0) and pk.compatibility < 1e-4
    fine = np.linspace(0, np.pi, 50 * (analytic["m"] - 1) + 1)
    hf = hmin_on(fine, analytic)
    k, dt = 9, 1e-4 * T
    psi = expected_psi(fine, times[k], hf, alpha0)[::50]
    assert np.max(np.abs(pk.psi[k] - psi)) < 2e-3 * np.max(np.abs(psi))
    # ψ is smooth in t when α₀ < π/2: v_θ = r ψ̇ against a central difference
    dpsi = (expected_psi(fine, times[k] + dt, hf, alpha0)
            - expected_psi(fine, times[k] - dt, hf, alpha0))[::50] / (2 * dt)
    v_theta = r_exact(phi, times[k]) * dpsi
    assert np.max(np.abs(pk.velocities[k, :, 2] - v_theta)) < 5e-3 * np.max(np.abs(v_theta))


def test_velocities_spectral_and_from_derivatives(analytic):
    pk, phi, times, K = analytic["pk"], analytic["phi"], analytic["times"], analytic["K"]
    dt = 1e-5 * T
    v_z = np.array([(z_exact(phi, t + dt) - z_exact(phi, t - dt)) / (2 * dt) for t in times])
    v_r = np.array([r_dt(phi, t) for t in times])
    scale = np.max(np.abs(v_z))
    assert np.max(np.abs(pk.velocities[..., 0] - v_r)) < 1e-5 * scale
    assert np.max(np.abs(pk.velocities[..., 1] - v_z)) < 1e-5 * scale
    # the caller's ∂c/∂t at fixed node (the nodes slide: φ_i depends on t)
    dshapes = np.array([(curve(t + dt) - curve(t - dt)) / (2 * dt) for t in times])
    pk2 = pellicle_kinematics(analytic["shapes"], T, m=analytic["m"], dshapes=dshapes)
    assert np.max(np.abs(pk2.velocities[..., 0] - v_r)) < 1e-5 * scale
    assert np.max(np.abs(pk2.velocities[..., 1] - v_z)) < 1e-5 * scale
    assert np.allclose(pk2.velocities[..., 2], pk.velocities[..., 2])
    assert K == len(pk.area)


def test_reference_pellicle_has_the_mean_area(analytic):
    pk = analytic["pk"]
    r0, z0 = pk.r0, pk.z0
    frustums = np.pi * np.sum((r0[1:] + r0[:-1]) * np.hypot(np.diff(r0), np.diff(z0)))
    assert abs(frustums - pk.area.mean()) / pk.area.mean() < 1e-3
    # and r ≥ r₀ at every sample, equality somewhere for every λ
    assert np.all(pk.positions[..., 0] >= r0 - 1e-14)
    assert np.allclose(pk.positions[..., 0].min(axis=0), r0)


def test_poles_finite_when_area_changes():
    th = np.linspace(0, np.pi, 201)
    K = 8
    b = 3.0 * (1 + 0.02 * np.cos(2 * np.pi * np.arange(K) / K))
    shapes = np.array([np.column_stack([bk * np.sin(th), 6.0 * np.cos(th)]) for bk in b])
    shapes[:, [0, -1], 0] = 0.0
    pk = pellicle_kinematics(shapes, 1.0, m=101)
    for a in (pk.shear, pk.psi, pk.velocities, pk.positions, pk.z0):
        assert np.all(np.isfinite(a))
    # r_φ² = S/4π at a pole, so γ there is √(S/S_min − 1), computed here from the areas
    g_pole = np.sqrt(pk.area / pk.area.min() - 1)
    assert np.allclose(pk.shear[:, 0], g_pole, atol=1e-4)
    assert np.allclose(pk.shear[:, -1], g_pole, atol=1e-4)
    assert np.all(pk.velocities[:, [0, -1], 0] == 0) and np.all(pk.velocities[:, [0, -1], 2] == 0)
    assert any("poles" in w for w in pk.warnings)


def test_poles_regular_for_area_preserving_stroke(analytic):
    pk, phi, hmin = analytic["pk"], analytic["phi"], analytic["hmin"]
    assert np.all(np.isfinite(pk.psi)) and np.all(np.isfinite(pk.velocities))
    assert np.max(pk.shear[:, [0, -1]]) < 1e-4 and not pk.warnings
    # ψ′ stays finite at the poles (0/0 in S8): the increments next to the poles match
    fine = np.linspace(0, np.pi, 50 * (analytic["m"] - 1) + 1)
    for k in (3, 17):
        psi = expected_psi(fine, analytic["times"][k], hmin_on(fine, analytic), np.pi / 2)
        d, d_exp = np.diff(pk.psi[k]), np.diff(psi[::50])
        ends = [0, 1, -2, -1]       # (ψ′ set to 0 at the poles would miss by ~30 %)
        assert np.max(np.abs(d[ends] - d_exp[ends])) < 1e-2 * np.max(np.abs(d_exp))


def _mushroom(rs=0.5, rb=1.6, n=400):
    a = np.linspace(0, np.pi / 2, 30)
    b = np.linspace(np.pi / 2, np.pi, 40)
    poly = np.vstack([np.column_stack([rs * np.sin(a), 2 + rs * np.cos(a)]),
                      np.column_stack([np.full(10, rs), np.linspace(2, 1, 10)])[1:],
                      np.column_stack([np.linspace(rs, rb, 20), np.full(20, 1.0)])[1:],
                      np.column_stack([rb * np.sin(b), 1 + rb * np.cos(b)])[1:]])
    d = np.concatenate([[0], np.cumsum(np.hypot(*np.diff(poly, axis=0).T))])
    s = np.linspace(0, d[-1], n)
    c = np.column_stack([np.interp(s, d, poly[:, 0]), np.interp(s, d, poly[:, 1])])
    c[[0, -1], 0] = 0.0
    return c


def test_unrealisable_reference_is_flagged():
    """A flat shoulder (z′ = 0, so |r′| = S/2πr) that is the thinnest shape there: S9 fails
    iff its area exceeds the mean."""
    th = np.linspace(0, np.pi, 400)
    sphere = np.column_stack([1.4 * np.sin(th), 1.4 * np.cos(th)])
    sphere[[0, -1], 0] = 0.0
    mush = _mushroom()
    pk = pellicle_kinematics(np.array([mush, sphere, sphere]), 1.0, max_area_deviation=None)
    assert pk.area[0] > pk.area.mean() and pk.not_realisable > 0
    assert any("not realisable" in w for w in pk.warnings)
    assert np.all(np.isfinite(pk.z0)) and np.all(np.diff(pk.z0) <= 1e-12)
    big = np.column_stack([2.2 * np.sin(th), 2.2 * np.cos(th)])
    big[[0, -1], 0] = 0.0
    pk = pellicle_kinematics(np.array([mush, big, big]), 1.0, max_area_deviation=None)
    assert pk.area[0] < pk.area.mean() and pk.not_realisable == 0


def test_bad_input():
    th = np.linspace(0, np.pi, 101)
    c = np.column_stack([np.sin(th), np.cos(th)])
    c[[0, -1], 0] = 0.0
    with pytest.raises(InputError, match="at least 3"):
        pellicle_kinematics(np.array([c, c]), 1.0)
    off = c.copy()
    off[0, 0] = 0.1
    with pytest.raises(InputError, match="axis"):
        pellicle_kinematics(np.array([c, off, c]), 1.0)
    with pytest.raises(InputError, match="top pole first"):
        pellicle_kinematics(np.array([c[::-1]] * 3), 1.0)
    big = c * [1.1, 1.0]
    with pytest.raises(InputError, match="max_area_deviation"):
        pellicle_kinematics(np.array([c, big, c]), 1.0)
    pk = pellicle_kinematics(np.array([c, big, c]), 1.0, max_area_deviation=None)
    assert pk.area_deviation > 0.05
    with pytest.raises(InputError, match="alpha0"):
        pellicle_kinematics(np.array([c] * 3), 1.0, alpha0=0.0)
    with pytest.raises(InputError, match="dshapes"):
        pellicle_kinematics(np.array([c] * 3), 1.0, dshapes=np.zeros((3, 5, 2)))
