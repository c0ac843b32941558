"""Analytic reference values for swimming spheres in Stokes flow (squirmers).

Conventions
-----------
* Sphere of radius ``a`` [m] in fluid of viscosity ``mu`` [Pa s]; spherical coordinates
  (r, θ) about the symmetry axis e_z, θ measured from +z, no swirl (u_φ = 0).
* Swimming velocities are along +z and positive when the body moves towards +z.
* The *body frame* translates with the body; "lab frame" flows vanish at infinity.
* Legendre modes P_m(cos θ) (radial) and Blake's tangential modes
  V_m(θ) = 2 sin θ P_m'(cos θ) / (m(m+1)),  V_1 = sin θ, V_2 = sin θ cos θ.

Exterior Stokes modes (Lamb 1932 §336; Happel & Brenner 1965 §4-2)
------------------------------------------------------------------
With u_r = -ψ_θ/(r² sin θ), u_θ = ψ_r/(r sin θ), the decaying solutions of E⁴ψ = 0 are
ψ = f(r) G_{m+1}(cos θ), f = a²[X (a/r)^m + Y (a/r)^(m-2)], and since
dG_{m+1}/dx = -P_m(x), G_{m+1}(cos θ)/sin θ = V_m/2:

    u_r = -f P_m / r²,    u_θ = f' V_m / (2r).                                      (1)

Surface data u_r = α_m P_m, u_θ = β_m V_m on r = a give f(a) = -a² α_m, f'(a) = 2a β_m:

    X = (m/2 - 1) α_m - β_m,    Y = β_m - m α_m / 2.                               (2)

The X term is a potential flow (p = 0); the Y term carries p = -μ c_m Y a^m r^(-m-1) P_m,
c_m = 2(2m-1)/(m+1).  For m = 1, Y is a Stokeslet: the force on the sphere is
F_z = 4πμ a Y_1, so a body is force free iff β_1 = α_1/2.                        (3)
On r = a the traction f = σ·e_r (fluid on body) of mode m is (derived from (1)-(2))

    f_r = -(μ/a) S_m P_m,   S_m = 4(α_m + β_m) - c_m Y,
    f_θ = (μ/a) T_m V_m,    T_m = [m(m+1) X + (m-1)(m-2) Y]/2 - 2β_m - m(m+1) α_m/2.   (4)

With ∫P_m² dx = 2/(2m+1), ∫V_m² dx = 8/(m(m+1)(2m+1)) (x = cos θ) the work rate of the
surface on the fluid, P = -∫ u·f dS = ∫ 2μ e:e dV, is a sum over modes

    P = 2πμa Σ_m [2 S_m α_m/(2m+1) - 8 T_m β_m/(m(m+1)(2m+1))].                     (5)

Reciprocal theorem (Lorentz; Stone & Samuel, PRL 77 (1996) 4102)
----------------------------------------------------------------
A sphere translating with Û e_z has the uniform traction f̂ = -(3μ/(2a)) Û e_z.  For a
force-free body whose surface moves with U e_z + u_s, ∫u·f̂ dS = ∫û·f dS = Û·F = 0, so

    U = -(1/(4πa²)) ∫_S u_s·e_z dS.                                                 (6)
"""
from __future__ import annotations

import numpy as np

# ----------------------------------------------------------------------------- modes


def legendre(m: int, x):
    """P_m(x) by Bonnet's recurrence (works on arrays and on symbolic x)."""
    p_prev, p = 1 + 0 * x, x
    if m == 0:
        return p_prev
    for k in range(1, m):
        p_prev, p = p, ((2 * k + 1) * x * p - k * p_prev) / (k + 1)
    return p


def legendre_derivative(m: int, x):
    """P_m'(x) from P'_{k+1} = P'_{k-1} + (2k+1) P_k (no division by 1 - x²)."""
    d_prev, d = 0 * x, 1 + 0 * x          # P_0', P_1'
    if m == 0:
        return d_prev
    for k in range(1, m):
        d_prev, d = d, d_prev + (2 * k + 1) * legendre(k, x)
    return d


def tangential_mode(m: int, theta):
    """Blake's V_m(θ) = 2 sin θ P_m'(cos θ)/(m(m+1)), dimensionless."""
    return 2 * np.sin(theta) * legendre_derivative(m, np.cos(theta)) / (m * (m + 1))


def tangential_mode_derivative(m: int, theta):
    """dV_m/dθ = 2 P_m - 2 cos θ P_m'/(m(m+1)) (Legendre's equation used)."""
    x = np.cos(theta)
    return 2 * legendre(m, x) - 2 * x * legendre_derivative(m, x) / (m * (m + 1))


def mode_coefficients(m: int, alpha, beta):
    """(X, Y) of eq. (2): f(r) = a²[X (a/r)^m + Y (a/r)^(m-2)] for surface data
    u_r = α P_m, u_θ = β V_m on r = a (α, β in m/s; X, Y in m/s).  Generic arithmetic."""
    return (m - 2) * alpha / 2 - beta, beta - m * alpha / 2


def _check_modes(modes: dict) -> dict:
    for m in modes:
        if not (isinstance(m, (int, np.integer)) and m >= 1):
            raise ValueError(f"mode numbers must be integers >= 1, got {m!r}")
    return {int(m): v for m, v in modes.items() if v != 0}


def _profile(m: int, alpha, beta, r, a: float):
    """f, f', f'' of eq. (1) at radius r [m] (units m³/s, m²/s, m/s)."""
    X, Y = mode_coefficients(m, alpha, beta)
    s = a / r
    f = a**2 * (X * s**m + Y * s ** (m - 2))
    df = -a * (m * X * s ** (m + 1) + (m - 2) * Y * s ** (m - 1))
    d2f = m * (m + 1) * X * s ** (m + 2) + (m - 2) * (m - 1) * Y * s**m
    return f, df, d2f


def exterior_flow(r, theta, radial: dict, tangential: dict, a: float = 1.0):
    """(u_r, u_θ) [m/s] of the exterior Stokes flow (vanishing at infinity) whose value on
    r = a is u_r = Σ α_m P_m(cos θ), u_θ = Σ β_m V_m(θ); ``radial`` = {m: α_m},
    ``tangential`` = {m: β_m} in m/s (complex amplitudes allowed), eqs. (1)-(2)."""
    radial, tangential = _check_modes(radial), _check_modes(tangential)
    r, theta = np.asarray(r, float), np.asarray(theta, float)
    ur, ut = 0j * r * theta, 0j * r * theta
    for m in sorted(set(radial) | set(tangential)):
        f, df, _ = _profile(m, radial.get(m, 0), tangential.get(m, 0), r, a)
        ur = ur - f * legendre(m, np.cos(theta)) / r**2
        ut = ut + df * tangential_mode(m, theta) / (2 * r)
    return _real_if_real(ur, radial, tangential), _real_if_real(ut, radial, tangential)


def exterior_flow_gradient(r, theta, radial: dict, tangential: dict, a: float = 1.0):
    """(∂_r u_r, ∂_θ u_r, ∂_r u_θ, ∂_θ u_θ) of :func:`exterior_flow` (units 1/s, m/s, 1/s,
    m/s), differentiated analytically from eq. (1); uses sin θ P_m' = m(m+1) V_m/2."""
    radial, tangential = _check_modes(radial), _check_modes(tangential)
    r, theta = np.asarray(r, float), np.asarray(theta, float)
    out = [0j * r * theta for _ in range(4)]
    for m in sorted(set(radial) | set(tangential)):
        f, df, d2f = _profile(m, radial.get(m, 0), tangential.get(m, 0), r, a)
        p, v = legendre(m, np.cos(theta)), tangential_mode(m, theta)
        out[0] = out[0] + (-df / r**2 + 2 * f / r**3) * p
        out[1] = out[1] + f * m * (m + 1) * v / (2 * r**2)
        out[2] = out[2] + (d2f / (2 * r) - df / (2 * r**2)) * v
        out[3] = out[3] + df * tangential_mode_derivative(m, theta) / (2 * r)
    return tuple(_real_if_real(g, radial, tangential) for g in out)


def _real_if_real(values, *mode_dicts):
    if all(np.isrealobj(np.asarray(list(d.values()) or [0.0])) for d in mode_dicts):
        return values.real
    return values


def traction_coefficients(m: int, alpha, beta):
    """(S_m, T_m, c_m Y) of eq. (4): on r = a, f_r = -(μ/a) S_m P_m, f_θ = (μ/a) T_m V_m
    and p = -(μ/a) c_m Y P_m; α, β in m/s."""
    X, Y = mode_coefficients(m, alpha, beta)
    cY = 2 * (2 * m - 1) * Y / (m + 1)
    S = 4 * (alpha + beta) - cY
    T = (m * (m + 1) * X + (m - 1) * (m - 2) * Y) / 2 - 2 * beta - m * (m + 1) * alpha / 2
    return S, T, cY


def exterior_power(radial: dict, tangential: dict, mu: float, a: float) -> float:
    """Work rate [W] of a sphere surface moving with the (real) data of
    :func:`exterior_flow` on the exterior fluid, eq. (5) (= the viscous dissipation)."""
    radial, tangential = _check_modes(radial), _check_modes(tangential)
    total = 0.0
    for m in set(radial) | set(tangential):
        alpha, beta = radial.get(m, 0.0), tangential.get(m, 0.0)
        S, T, _ = traction_coefficients(m, alpha, beta)
        total += 2 * S * alpha / (2 * m + 1) - 8 * T * beta / (m * (m + 1) * (2 * m + 1))
    return 2 * np.pi * mu * a * total


# ------------------------------------------------------------ 1. steady squirmer


def squirmer_speed(B1, B2=0.0):
    """Free-swimming speed U [m/s] along +z of the squirmer with body-frame slip
    u_θ = B1 sin θ + B2 sin θ cos θ (Lighthill 1952, Blake 1971): U = 2 B1/3.

    From (6) with u_s = u_θ e_θ, e_θ·e_z = -sin θ: U = (1/2)∫(B1 + B2 x)(1 - x²) dx.
    B1 > 0 drives the surface from the +z pole towards -z, so the body swims to +z; B2
    does not contribute.  Generic arithmetic (floats, arrays, symbols).
    """
    return 2 * B1 / 3


def squirmer_lab_modes(B1, B2=0.0):
    """Lab-frame surface data ({m: α_m}, {m: β_m}) [m/s] of the free squirmer:
    u = U e_z + u_θ e_θ with e_z = P_1 e_r - V_1 e_θ, so α_1 = U, β_1 = B1 - U, β_2 = B2.
    α_1 = 2β_1 is the force-free condition (3)."""
    U = squirmer_speed(B1)
    return {1: U}, {1: B1 - U, 2: B2}


def squirmer_flow(r, theta, B1, B2=0.0, a: float = 1.0):
    """Lab-frame (u_r, u_θ) [m/s] of the free squirmer (Blake 1971, eqs. (1)-(2)):
    u_r = (2B1/3)(a/r)³ P_1 + B2[(a/r)⁴ - (a/r)²] P_2,
    u_θ = (B1/3)(a/r)³ sin θ + B2 (a/r)⁴ sin θ cos θ."""
    return exterior_flow(r, theta, *squirmer_lab_modes(B1, B2), a=a)


def squirmer_power(B1, B2, mu, a):
    """Power [W] dissipated in the fluid by the free squirmer, P = (16π/3) μ a (B1² + B2²/2).

    Derivation: the lab-frame modes (α_1, β_1) = (2B1/3, B1/3) (Y_1 = 0, potential dipole)
    and (α_2, β_2) = (0, B2) (X_2 = -B2, Y_2 = B2, stresslet + quadrupole) give by (4)
    f = -(μ/a)[4B1 cos θ + 2B2 P_2] e_r - (μ/a)[2B1 sin θ + 5B2 sin θ cos θ] e_θ
    (∫f_z dS = 0: force free).  P = -∫u·f dS = 2πa²(μ/a)∫_{-1}^{1} [(2B1/3)x(4B1 x + 2B2 P_2)
    + (B1/3 + B2 x)(2B1 + 5B2 x)(1 - x²)] dx = 2πμa[16/9 + 8/9] B1² + 2πμa (4/3) B2².
    Efficiency 6πμaU²/P = B1²/(2B1² + B2²), i.e. 1/2 for B2 = 0.
    """
    return 16 * np.pi / 3 * mu * a * (B1**2 + B2**2 / 2)


def squirmer_efficiency(B1, B2=0.0):
    """Lighthill efficiency 6πμaU²/P = B1²/(2B1² + B2²) (dimensionless)."""
    B1, B2 = np.asarray(B1, float), np.asarray(B2, float)
    return B1**2 / (2 * B1**2 + B2**2)


# ------------------------------------------- 2. small-amplitude deforming sphere


def first_order_velocity(radial: dict, tangential: dict, a: float = 1.0,
                         omega: float = 1.0) -> complex:
    """Complex amplitude Û₁ [m/s] of the first-order velocity, U = ε Re(Û₁ e^{-iωt}) + O(ε²).

    The surface velocity ∂ξ/∂t has amplitudes -iωa A_m (on P_m e_r) and -iωa B_m (on V_m e_θ);
    with e_z = P_1 e_r - V_1 e_θ the force-free condition (3), β_1 = α_1/2, for
    α_1 = -iωa A_1 + Û₁, β_1 = -iωa B_1 - Û₁ gives Û₁ = -iωa (2B_1 - A_1)/3 (also eq. (6)).
    """
    radial, tangential = _check_modes(radial), _check_modes(tangential)
    return -1j * omega * a * (2 * tangential.get(1, 0) - radial.get(1, 0)) / 3


def first_order_surface_modes(radial: dict, tangential: dict, a: float = 1.0,
                              omega: float = 1.0):
    """({m: α_m}, {m: β_m}) [m/s]: complex lab-frame velocity amplitudes of u₁ on r = a,
    u₁ = ∂ξ₁/∂t + U₁ e_z, force free (Y_1 = 0)."""
    radial, tangential = _check_modes(radial), _check_modes(tangential)
    U1 = first_order_velocity(radial, tangential, a, omega)
    alpha = {m: -1j * omega * a * A for m, A in radial.items()}
    beta = {m: -1j * omega * a * B for m, B in tangential.items()}
    alpha[1] = alpha.get(1, 0) + U1
    beta[1] = beta.get(1, 0) - U1
    return alpha, beta


def gauss_nodes(n: int):
    """θ_k and weights w_k of n-point Gauss–Legendre quadrature in x = cos θ on [-1, 1]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return np.arccos(x), w


def reciprocal_velocity(us_r, us_theta, theta, weights):
    """Eq. (6) by quadrature: U = -(1/2) Σ_k w_k [u_s,r cos θ_k - u_s,θ sin θ_k] [m/s] for an
    axisymmetric surface velocity u_s (body frame, m/s) sampled at :func:`gauss_nodes`."""
    uz = np.asarray(us_r) * np.cos(theta) - np.asarray(us_theta) * np.sin(theta)
    return -0.5 * np.sum(np.asarray(weights) * uz, axis=-1)


def second_order_mean_velocity(radial: dict, tangential: dict, a: float = 1.0,
                               omega: float = 1.0) -> float:
    """Ū₂ [m/s]: the period-averaged swimming velocity along +z is ε² Ū₂ + O(ε⁴), for the
    displacement ξ = ε a Re[e^{-iωt}(Σ A_n P_n e_r + Σ B_n V_n e_θ)], ``radial`` = {n: A_n},
    ``tangential`` = {n: B_n} (complex, dimensionless).  Ū₂ ∝ aω: with a = ω = 1 it is the
    coefficient in units of aω.

    Method (Felderhof & Jones, Physica A 202 (1994) 94 and 119; Lauga, Soft Matter 7 (2011)
    3060 §3): no slip on the displaced surface, u(x0 + ξ) = ∂ξ/∂t + U e_z, expanded about
    S0 gives u₁ = ∂ξ₁/∂t + U₁ e_z and u₂ = U₂ e_z - (ξ₁·∇)u₁ on S0 (the second-order
    material displacement is zero here; it would only add a zero-mean ∂ξ₂/∂t).  Since σ₁ is
    solenoidal between S0 and S(t), force free at O(ε²) means ∫_{S0} σ₂·e_r dS = 0, and (6)
    with u_s = -(ξ₁·∇)u₁ gives Ū₂ = (1/(4πa²)) ∫_{S0} ⟨[(ξ₁·∇)u₁]·e_z⟩ dS, where
    [(ξ·∇)u]_r = ξ_r ∂_r u_r + (ξ_θ/r)(∂_θ u_r - u_θ),
    [(ξ·∇)u]_θ = ξ_r ∂_r u_θ + (ξ_θ/r)(∂_θ u_θ + u_r)
    and ⟨Re(p e^{-iωt}) Re(q e^{-iωt})⟩ = Re(p̄ q)/2.  u₁ and ∇u₁ come from eqs. (1)-(2)
    with :func:`first_order_surface_modes`; the θ integrand is a polynomial in cos θ of
    degree <= 2N + 2, integrated exactly by (N + 4)-point Gauss–Legendre quadrature.
    Modes n = 1 are allowed; adding a rigid oscillation (A_1, B_1) = (c, -c) only moves the
    body-frame origin and leaves Ū₂ unchanged.  Examples: A_2 = 1, A_3 = i gives -3/70;
    A_2 = 1, B_3 = i gives 6/35; real (in-phase) amplitudes give 0 (scallop theorem).
    """
    radial, tangential = _check_modes(radial), _check_modes(tangential)
    if not radial and not tangential:
        return 0.0
    n_max = max(set(radial) | set(tangential))
    theta, w = gauss_nodes(n_max + 4)
    g_r, g_t = mean_convective_term(theta, radial, tangential, a, omega)
    return float(reciprocal_velocity(-g_r, -g_t, theta, w))


def mean_convective_term(theta, radial: dict, tangential: dict, a: float = 1.0,
                         omega: float = 1.0):
    """(⟨[(ξ₁·∇)u₁]_r⟩, ⟨[(ξ₁·∇)u₁]_θ⟩) on r = a at angles θ [m/s, per ε²]; the arguments
    are those of :func:`second_order_mean_velocity`."""
    alpha, beta = first_order_surface_modes(radial, tangential, a, omega)
    x = np.cos(theta)
    xi_r = np.conj(sum((a * A * legendre(n, x) for n, A in radial.items()), 0 * x))
    xi_t = np.conj(sum((a * B * tangential_mode(n, theta) for n, B in tangential.items()), 0 * x))
    ur, ut = exterior_flow(a, theta, alpha, beta, a)
    dr_ur, dt_ur, dr_ut, dt_ut = exterior_flow_gradient(a, theta, alpha, beta, a)
    g_r = xi_r * dr_ur + xi_t * (dt_ur - ut) / a
    g_t = xi_r * dr_ut + xi_t * (dt_ut + ur) / a
    return 0.5 * np.real(g_r), 0.5 * np.real(g_t)


def net_displacement_per_period(radial: dict, tangential: dict, epsilon: float,
                                a: float = 1.0, omega: float = 1.0) -> float:
    """Net displacement [m] along +z per period 2π/ω: ε² Ū₂ 2π/ω (independent of ω)."""
    return epsilon**2 * second_order_mean_velocity(radial, tangential, a, omega) * 2 * np.pi / omega
