"""Tests of pointatlas_studies.squirming_sphere_theory.

Independent routes: the Stokes modes and tractions are re-derived symbolically (sympy, in
x = cos θ so that every expression is a polynomial/rational function); the power is checked
against the volume integral of 2μ e:e over the whole exterior (s = a/r maps r ∈ [a, ∞) onto
(0, 1] with a polynomial integrand); the second-order mean velocity is checked against a
finite-amplitude computation that imposes no slip *on the displaced surface itself* (no
Taylor expansion, no reciprocal theorem, no velocity gradients) and extracts the ε²
coefficient of the period-mean velocity by Richardson extrapolation in ε.
"""
import numpy as np
import pytest
import sympy as sp

import pointatlas_studies.squirming_sphere_theory as th

r, a, mu = sp.symbols("r a mu", positive=True)
x = sp.Symbol("x")                       # cos θ
E2 = lambda g: sp.diff(g, r, 2) + (1 - x**2) / r**2 * sp.diff(g, x, 2)  # noqa: E731


def symbolic_mode(m, alpha, beta):
    """ψ, u_r, w = u_θ/sin θ and p of mode m, built from the module's (X, Y) and c_m Y."""
    X, Y = th.mode_coefficients(m, alpha, beta)
    f = a**2 * (X * (a / r) ** m + Y * (a / r) ** (m - 2))
    P = sp.legendre(m, x)
    dP = sp.diff(P, x)
    psi = f * (1 - x**2) * dP / (m * (m + 1))
    ur = -f * P / r**2                                   # eq. (1)
    w = sp.diff(f, r) * (2 * dP / (m * (m + 1))) / (2 * r)   # u_θ = f' V_m/(2r), V_m/sin θ
    cY = th.traction_coefficients(m, alpha, beta)[2]
    p = -mu / a * cY * (a / r) ** (m + 1) * P
    return psi, ur, w, p


def stress(ur, w, p):
    """σ_rr and σ_rθ/sin θ (∂_θ = -sin θ ∂_x)."""
    return (-p + 2 * mu * sp.diff(ur, r),
            mu * (sp.diff(w, r) - w / r - sp.diff(ur, x) / r))


def field(modes):
    """Sum of symbolic modes {m: (α, β)}: (u_r, w, p)."""
    parts = [symbolic_mode(m, al, be)[1:] for m, (al, be) in modes.items()]
    return tuple(sum(q[i] for q in parts) for i in range(3))


@pytest.mark.parametrize("m", range(1, 9))
def test_modes_solve_stokes_with_the_boundary_data_symbolically(m):
    al, be = sp.symbols("alpha beta")
    psi, ur, w, p = symbolic_mode(m, al, be)
    zero = lambda e: sp.simplify(sp.expand(e)) == 0  # noqa: E731
    # ψ is f(r) times the Gegenbauer function G_{m+1} = (P_{m-1} - P_{m+1})/(2m+1)
    G = (sp.legendre(m - 1, x) - sp.legendre(m + 1, x)) / (2 * m + 1)
    assert zero((1 - x**2) * sp.diff(sp.legendre(m, x), x) / (m * (m + 1)) - G)
    # velocities from the stream function: u_r = -ψ_θ/(r² sin θ), u_θ = ψ_r/(r sin θ)
    assert zero(ur - sp.diff(psi, x) / r**2)
    assert zero(w - sp.diff(psi, r) / (r * (1 - x**2)))
    # incompressible, E⁴ψ = 0, and ∇p = μ∇²u = -μ∇×ω with ω = (E²ψ/(r sin θ)) e_φ
    assert zero(sp.diff(r**2 * ur, r) / r**2 - sp.diff((1 - x**2) * w, x) / r)
    assert zero(E2(E2(psi)))
    assert zero(sp.diff(p, r) - mu / r**2 * sp.diff(E2(psi), x))
    assert zero((1 - x**2) * sp.diff(p, x) + mu * sp.diff(E2(psi), r))
    # boundary data and decay
    Vm_over_sin = 2 * sp.diff(sp.legendre(m, x), x) / (m * (m + 1))
    assert zero(ur.subs(r, a) - al * sp.legendre(m, x))
    assert zero(w.subs(r, a) - be * Vm_over_sin)
    assert sp.limit(ur, r, sp.oo) == 0 and sp.limit(w, r, sp.oo) == 0
    # the traction formulas (4)
    S, T, _ = th.traction_coefficients(m, al, be)
    srr, srt = stress(ur, w, p)
    assert zero(srr.subs(r, a) + mu / a * S * sp.legendre(m, x))
    assert zero(srt.subs(r, a) - mu / a * T * Vm_over_sin)


def test_numeric_fields_match_the_symbolic_ones():
    rng = np.random.default_rng(0)
    modes = {m: tuple(complex(*rng.normal(size=2)) for _ in range(2)) for m in range(1, 9)}
    ur, w, _ = field({m: (sp.Symbol(f"al{m}"), sp.Symbol(f"be{m}")) for m in modes})
    subs = {sp.Symbol(f"al{m}"): v[0] for m, v in modes.items()}
    subs.update({sp.Symbol(f"be{m}"): v[1] for m, v in modes.items()})
    ur, w = ur.subs(subs).subs(a, 1.3), w.subs(subs).subs(a, 1.3)
    s = sp.sqrt(1 - x**2)
    exprs = [ur, s * w, sp.diff(ur, r), -s * sp.diff(ur, x), s * sp.diff(w, r),
             x * w - (1 - x**2) * sp.diff(w, x)]
    rr, tt = rng.uniform(1.3, 4.0, 7), rng.uniform(0.05, 3.1, 7)
    want = [sp.lambdify((r, x), e, "numpy")(rr, np.cos(tt)) for e in exprs]
    radial = {m: v[0] for m, v in modes.items()}
    tangential = {m: v[1] for m, v in modes.items()}
    got = [*th.exterior_flow(rr, tt, radial, tangential, a=1.3),
           *th.exterior_flow_gradient(rr, tt, radial, tangential, a=1.3)]
    for g, e in zip(got, want):
        np.testing.assert_allclose(g, e, rtol=1e-11, atol=1e-12)


# -------------------------------------------------------------- steady squirmer


def dissipation(ur, w, mu_value, a_value, n=24):
    """∫ 2μ e:e dV over r ∈ [a, ∞) by Gauss–Legendre in s = a/r ∈ (0, 1] and x."""
    err = sp.diff(ur, r)
    ett = (x * w - (1 - x**2) * sp.diff(w, x)) / r + ur / r
    epp = ur / r + x * w / r
    ert2 = (1 - x**2) * (sp.diff(w, r) - w / r - sp.diff(ur, x) / r) ** 2 / 4
    ee = (err**2 + ett**2 + epp**2 + 2 * ert2).subs(a, a_value)
    fn = sp.lambdify((r, x), ee, "numpy")
    q, wq = np.polynomial.legendre.leggauss(n)
    s, ws = (q + 1) / 2, wq / 2
    S, Xg = np.meshgrid(s, q, indexing="ij")
    vals = fn(a_value / S, Xg) * a_value**3 / S**4            # r² dr = a³ s⁻⁴ ds
    return 2 * mu_value * 2 * np.pi * np.einsum("i,j,ij", ws, wq, vals)


def test_squirmer_flow_is_the_force_free_lab_flow_and_its_power():
    B1, B2 = sp.symbols("B1 B2")
    radial, tangential = th.squirmer_lab_modes(B1, B2)
    ur, w, p = field({1: (radial[1], tangential[1]), 2: (0, tangential[2])})
    U = th.squirmer_speed(B1, B2)
    assert U == 2 * B1 / 3
    # body-frame slip on r = a: u - U e_z = (B1 + B2 cos θ) sin θ e_θ (e_z = x e_r - sin θ e_θ)
    assert sp.simplify(ur.subs(r, a) - U * x) == 0
    assert sp.simplify(w.subs(r, a) + U - (B1 + B2 * x)) == 0
    srr, srt = (e.subs(r, a) for e in stress(ur, w, p))
    dS = 2 * sp.pi * a**2
    assert sp.simplify(dS * sp.integrate(srr * x - (1 - x**2) * srt, (x, -1, 1))) == 0  # F = 0
    P = -dS * sp.integrate((ur * srr + (1 - x**2) * w * srt).subs(r, a), (x, -1, 1))
    assert sp.simplify(P - 16 * sp.pi / 3 * mu * a * (B1**2 + B2**2 / 2)) == 0
    # numerically: the module's field equals the symbolic one; power = volume dissipation
    vals = {B1: 0.7, B2: -1.9}
    rr, tt = np.array([1.0, 1.7, 5.0]), np.array([0.3, 1.2, 2.9])
    ur_n, ut_n = th.squirmer_flow(rr * 1.5, tt, 0.7, -1.9, a=1.5)
    want = sp.lambdify((r, x), ur.subs(vals).subs(a, 1.5))(rr * 1.5, np.cos(tt))
    np.testing.assert_allclose(ur_n, want, rtol=1e-13)
    np.testing.assert_allclose(ur_n[0], th.squirmer_speed(0.7) * np.cos(0.3), rtol=1e-13)
    P_vol = dissipation(ur.subs(vals), w.subs(vals), 2.3, 1.5)
    np.testing.assert_allclose(P_vol, th.squirmer_power(0.7, -1.9, 2.3, 1.5), rtol=1e-10)
    np.testing.assert_allclose(th.exterior_power({1: 0.7 * 2 / 3}, {1: 0.7 / 3, 2: -1.9}, 2.3, 1.5),
                               th.squirmer_power(0.7, -1.9, 2.3, 1.5), rtol=1e-13)
    assert th.squirmer_efficiency(0.7) == pytest.approx(0.5)
    eff = 6 * np.pi * 2.3 * 1.5 * th.squirmer_speed(0.7) ** 2 / th.squirmer_power(0.7, 0, 2.3, 1.5)
    assert eff == pytest.approx(0.5, rel=1e-14)


def test_exterior_power_is_the_volume_dissipation_for_general_modes():
    rng = np.random.default_rng(1)
    modes = {m: tuple(rng.normal(size=2)) for m in range(1, 5)}       # with a net force too
    ur, w, _ = field(modes)
    P_vol = dissipation(ur, w, 0.9, 0.8)
    P = th.exterior_power({m: v[0] for m, v in modes.items()},
                          {m: v[1] for m, v in modes.items()}, 0.9, 0.8)
    np.testing.assert_allclose(P, P_vol, rtol=1e-10)


def test_squirmer_speed_from_the_reciprocal_theorem():
    theta, wq = th.gauss_nodes(8)
    for B1, B2 in [(1.0, 0.0), (0.0, 1.0), (-0.4, 2.0)]:
        slip = B1 * np.sin(theta) + B2 * np.sin(theta) * np.cos(theta)
        U = th.reciprocal_velocity(0 * theta, slip, theta, wq)
        assert U == pytest.approx(th.squirmer_speed(B1, B2), abs=1e-15)
    assert th.squirmer_speed(1.0) > 0                 # swims towards +z


# ------------------------------------------------- second-order mean velocity

def finite_amplitude_mean_velocity(radial, tangential, eps, n_modes=32, n_points=96, n_times=12):
    """Period mean of U(t) for the *exact* no-slip condition on the displaced surface.

    At each time the material points x0 + ξ (moving with ∂ξ/∂t) get lab velocity
    U e_z + ∂ξ/∂t; the flow is a least-squares sum of a source and the exterior modes
    m = 1..n_modes about the body-frame origin with the Stokeslet omitted (force free).
    """
    theta, _ = th.gauss_nodes(n_points)
    c, s = np.cos(theta), np.sin(theta)
    A = sum((amp * th.legendre(n, c) for n, amp in radial.items()), 0 * c)
    B = sum((amp * th.tangential_mode(n, theta) for n, amp in tangential.items()), 0 * c)
    basis = [("source", 0, 0)] + [(m, 1.0, 0.5 if m == 1 else 0.0) for m in range(1, n_modes + 1)]
    basis += [(m, 0.0, 1.0) for m in range(2, n_modes + 1)]       # β_1 = α_1/2: no Stokeslet
    U = []
    for t in 2 * np.pi * np.arange(n_times) / n_times:
        e = np.exp(-1j * t)
        xr, xt = eps * np.real(A * e), eps * np.real(B * e)
        vr, vt = eps * np.real(-1j * A * e), eps * np.real(-1j * B * e)
        rho, z = (1 + xr) * s + xt * c, (1 + xr) * c - xt * s
        R, TH = np.hypot(rho, z), np.arctan2(rho, z)
        cols = []
        for m, al, be in basis:
            ur, ut = (R**-2, 0 * R) if m == "source" else th.exterior_flow(R, TH, {m: al}, {m: be})
            cols.append(np.concatenate([ur * np.sin(TH) + ut * np.cos(TH),
                                        ur * np.cos(TH) - ut * np.sin(TH)]))
        cols.append(np.concatenate([0 * c, -np.ones_like(c)]))
        rhs = np.concatenate([vr * s + vt * c, vr * c - vt * s])
        sol, *_ = np.linalg.lstsq(np.array(cols).T, rhs, rcond=None)
        U.append(sol[-1])
    return np.mean(U)


def richardson_second_order(radial, tangential, eps=5e-3, **kw):
    """ε² coefficient of the (even) mean velocity from ε, 2ε, 3ε (error O(ε⁶))."""
    k = np.array([1.0, 2.0, 3.0])
    vals = [finite_amplitude_mean_velocity(radial, tangential, kk * eps, **kw) / (kk * eps) ** 2
            for kk in k]
    return np.linalg.solve(np.column_stack([k**0, k**2, k**4]), vals)[0]


STROKES = {
    "A2=1,A3=i": ({2: 1.0, 3: 1j}, {}),
    "A2=1,B3=i": ({2: 1.0}, {3: 1j}),
}


@pytest.mark.parametrize("name", STROKES)
def test_second_order_values_against_finite_amplitude_no_slip(name):
    radial, tangential = STROKES[name]
    U2 = th.second_order_mean_velocity(radial, tangential)
    print(f"\n{name}: U2 = {U2:.15f} a omega")
    assert U2 != 0
    U2_finite = richardson_second_order(radial, tangential, n_modes=20, n_points=64)
    assert U2_finite == pytest.approx(U2, rel=1e-8)


def test_second_order_with_all_modes_up_to_8_against_finite_amplitude():
    rng = np.random.default_rng(3)
    radial = {n: complex(*rng.normal(size=2)) / n for n in range(1, 9)}
    tangential = {n: complex(*rng.normal(size=2)) / n for n in range(1, 9)}
    U2 = th.second_order_mean_velocity(radial, tangential)
    assert richardson_second_order(radial, tangential, eps=2e-3) == pytest.approx(U2, rel=1e-8)


def test_closed_forms_of_the_two_strokes():
    """Exact rationals found by this module (and confirmed by the finite-amplitude test)."""
    assert th.second_order_mean_velocity(*STROKES["A2=1,A3=i"]) == pytest.approx(-3 / 70, 1e-14)
    assert th.second_order_mean_velocity(*STROKES["A2=1,B3=i"]) == pytest.approx(6 / 35, 1e-14)


def test_first_order_velocity_is_force_free_and_matches_the_reciprocal_theorem():
    rng = np.random.default_rng(4)
    radial = {n: complex(*rng.normal(size=2)) for n in range(1, 5)}
    tangential = {n: complex(*rng.normal(size=2)) for n in range(1, 5)}
    alpha, beta = th.first_order_surface_modes(radial, tangential, a=2.0, omega=3.0)
    assert abs(th.mode_coefficients(1, alpha[1], beta[1])[1]) < 1e-14   # no Stokeslet
    theta, wq = th.gauss_nodes(10)
    vr = sum(-3j * 2.0 * A * th.legendre(n, np.cos(theta)) for n, A in radial.items())
    vt = sum(-3j * 2.0 * B * th.tangential_mode(n, theta) for n, B in tangential.items())
    U1 = th.first_order_velocity(radial, tangential, a=2.0, omega=3.0)
    assert th.reciprocal_velocity(vr, vt, theta, wq) == pytest.approx(U1, abs=1e-13)


def test_reciprocal_stroke_does_not_swim():
    rng = np.random.default_rng(5)
    radial = {n: rng.normal() for n in range(1, 9)}
    tangential = {n: rng.normal() for n in range(1, 9)}
    assert abs(th.second_order_mean_velocity(radial, tangential)) < 1e-15
    phase = np.exp(0.83j)
    assert abs(th.second_order_mean_velocity({n: phase * v for n, v in radial.items()},
                                             {n: phase * v for n, v in tangential.items()})) < 1e-14


def test_rigid_oscillation_has_no_mean_velocity():
    """ξ = εa cos(ωt) e_z: A_1 = 1, B_1 = -1 (e_z = P_1 e_r - V_1 e_θ).  Force free at
    first order gives U₁ = -∂ξ_z/∂t = εaω sin ωt (Û₁ = iωa): the centre stays at rest,
    u₁ ≡ 0, so the body-frame velocity has zero mean, U₂ = 0."""
    radial, tangential = {1: 1.0 + 0j}, {1: -1.0 + 0j}
    assert th.first_order_velocity(radial, tangential, a=2.0, omega=3.0) == pytest.approx(6j)
    alpha, beta = th.first_order_surface_modes(radial, tangential, a=2.0, omega=3.0)
    assert alpha == {1: 0} and beta == {1: 0}
    assert th.second_order_mean_velocity(radial, tangential, a=2.0, omega=3.0) == 0
    assert abs(finite_amplitude_mean_velocity(radial, tangential, 0.05)) < 1e-15


def test_moving_the_body_frame_origin_does_not_change_the_mean_velocity():
    """Adding a rigid oscillation c e_z to ξ only relabels the origin (X' = X - εa Re(c e^{-iωt})),
    so Ū₂ is unchanged; in the formula this needs ∫_{S0} ∂_z u₁·e_z dS = 0 (force free)."""
    radial, tangential = {2: 0.3 + 1j, 3: -0.5, 5: 0.2j}, {2: 0.7j, 4: -0.4 + 0.1j}
    U2 = th.second_order_mean_velocity(radial, tangential)
    c = 0.6 - 1.3j
    shifted = th.second_order_mean_velocity({**radial, 1: c}, {**tangential, 1: -c})
    assert shifted == pytest.approx(U2, rel=1e-13)


def test_symmetries_and_scaling():
    radial, tangential = {1: 0.2, 2: 1.0, 3: 0.4j}, {2: -0.3j, 3: 0.5, 6: 0.1 + 0.2j}
    U2 = th.second_order_mean_velocity(radial, tangential)
    assert abs(U2) > 1e-3
    scale = lambda k: th.second_order_mean_velocity(  # noqa: E731
        {n: k * v for n, v in radial.items()}, {n: k * v for n, v in tangential.items()})
    assert scale(np.exp(2.1j)) == pytest.approx(U2, rel=1e-13)         # common phase
    assert scale(2.5) == pytest.approx(6.25 * U2, rel=1e-13)           # |amplitude|²
    conj = th.second_order_mean_velocity({n: np.conj(v) for n, v in radial.items()},
                                         {n: np.conj(v) for n, v in tangential.items()})
    assert conj == pytest.approx(-U2, rel=1e-13)                       # time reversal
    assert th.second_order_mean_velocity(radial, tangential, a=2.0, omega=3.0) \
        == pytest.approx(6 * U2, rel=1e-13)                            # Ū₂ ∝ aω
    assert th.net_displacement_per_period(radial, tangential, 0.1, a=2.0, omega=3.0) \
        == pytest.approx(0.01 * 2 * U2 * 2 * np.pi, rel=1e-13)


def test_bad_mode_numbers_are_rejected():
    with pytest.raises(ValueError):
        th.second_order_mean_velocity({0: 1.0}, {})
    with pytest.raises(ValueError):
        th.second_order_mean_velocity({}, {2.5: 1.0})
