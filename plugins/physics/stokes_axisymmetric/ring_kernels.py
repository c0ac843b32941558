"""Ring kernels: the free-space Stokeslet and stresslet integrated over the azimuth.

A ring of radius r at height z (the source point y on the generating curve) acts on a
field point x₀ = (r₀, 0, z₀). With d = x₀ − y(φ) = (r₀ − r cos φ, −r sin φ, z₀ − z),
ρ = |d|, the azimuthal moments L_{n,m} = ∫ uⁿ/ρ^m dφ of :mod:`.azimuthal_moments`
(u = 1 − cos φ, a = r² + r₀² + Δz², b = 2 r r₀) and the differences Δr = r₀ − r,
Δz = z₀ − z, every kernel is ∫_0^{2π} (polynomial in u) / ρ^m · r dφ (r dφ: the ring's
arclength). Components are cylindrical: radial (r), axial (z) and azimuthal (φ), each in
the local basis at its point. In u: d·e_r(x₀) = Δr + r u, d·e_r(y) = Δr − r₀ u,
d·e_φ(y) = −r₀ sin φ, sin²φ = 2u − u².

Single layer (Stokeslet G_ij = δ_ij/ρ + d_i d_j/ρ³, Pozrikidis 1992 Eq. 2.2.8; velocity
u(x₀) = (1/8πμ) ∫ M f dℓ, f the force density per unit area):

    M_rr = r [L_{0,1} − L_{1,1} + Δr² L_{0,3} − Δr² L_{1,3} − r r₀ L_{2,3}]
    M_rz = r Δz (Δr L_{0,3} + r L_{1,3}),    M_zr = r Δz (Δr L_{0,3} − r₀ L_{1,3})
    M_zz = r (L_{0,1} + Δz² L_{0,3}),
    M_φφ = r [L_{0,1} − L_{1,1} + r r₀ (2L_{1,3} − L_{2,3})]

The swirl (φ) decouples from the meridional (r, z) problem. Near the ring (ρ_m → 0 in the
meridian plane) M_rr, M_zz ~ −2 ln ρ_m and M_φφ ~ −4 ln ρ_m (a straight line of Stokeslets).

Double layer (stresslet T_ijk(y − x₀) = −(3/4π) (y−x₀)_i (y−x₀)_j (y−x₀)_k / ρ⁵, Pozrikidis
1992 Eq. 2.3.8 with the SI's 1/8π folded in, Arroyo et al. 2012 Eq. S10):
W_i(x₀) = ∫ T_ijk v_j n_k dS = (3/4π) ∫ d_i (d·v)(d·n)/ρ⁵ r dφ dℓ, with
d·n = (n_r Δr + n_z Δz) − n_r r₀ u for the normal (n_r, n_z) at y:

    D_{iβ} = (3r/4π) ∫ (d·e_i)(d·e_β(y))(d·n) / ρ⁵ dφ,     i, β ∈ {r, z}
    D_φφ   = (3r/4π) ∫ r r₀ sin²φ (d·n) / ρ⁵ dφ

and, for the subtraction of a constant Cartesian density v(x₀) (:func:`double_layer_constant`),
the same with d·e_x = Δr + r u (meridional) and d_y² = r² sin²φ (swirl). On a closed surface
∫ T_ijk n_k dS = −½ δ_ij at a point of the surface (0 outside, −δ_ij inside).
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from .azimuthal_moments import INDEX, azimuthal_moments


def _geometry(x0, y):
    x0 = np.asarray(x0, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    r0, z0 = x0[..., 0], x0[..., 1]
    r, z = y[..., 0], y[..., 1]
    dr, dz = r0 - r, z0 - z
    a = r * r + r0 * r0 + dz * dz
    b = 2.0 * r * r0
    return r0, r, dr, dz, azimuthal_moments(a, b, dr * dr + dz * dz)


def single_layer(x0, y):
    """(M_rr, M_rz, M_zr, M_zz, M_φφ) of the ring through y at x₀ (module doc); x₀, y
    (…, 2) as (r, z) (length), broadcast together; result (…, 5) in length⁰ (ring Jacobian r
    included, the 1/8πμ not)."""
    r0, r, dr, dz, L = _geometry(x0, y)
    g = lambda n, m: L[..., INDEX[(n, m)]]  # noqa: E731
    out = np.empty(L.shape[:-1] + (5,))
    out[..., 0] = r * (g(0, 1) - g(1, 1) + dr * dr * (g(0, 3) - g(1, 3)) - r * r0 * g(2, 3))
    out[..., 1] = r * dz * (dr * g(0, 3) + r * g(1, 3))
    out[..., 2] = r * dz * (dr * g(0, 3) - r0 * g(1, 3))
    out[..., 3] = r * (g(0, 1) + dz * dz * g(0, 3))
    out[..., 4] = r * (g(0, 1) - g(1, 1) + r * r0 * (2.0 * g(1, 3) - g(2, 3)))
    return out


assert all(INDEX[(n, 5)] == 5 + n for n in range(4))  # the layout _moment5 reads


@njit(cache=True)
def _mul21(p0, p1, q0, q1):
    """(p0 + p1 u)(q0 + q1 u), coefficients lowest first."""
    return p0 * q0, p0 * q1 + p1 * q0, p1 * q1


@njit(cache=True)
def _mul31(p0, p1, p2, q0, q1):
    """(p0 + p1 u + p2 u²)(q0 + q1 u), coefficients lowest first."""
    return p0 * q0, p0 * q1 + p1 * q0, p1 * q1 + p2 * q0, p2 * q1


@njit(cache=True)
def _moment5(L, p):
    """Σ_n p_n L_{n,5} for a cubic p (columns 5…8 of ``PAIRS`` hold (0,5) … (3,5))."""
    return p[0] * L[5] + p[1] * L[6] + p[2] * L[7] + p[3] * L[8]


@njit(cache=True, parallel=True)
def _double_layer_kernel(r0, r, dr, dz, nr, nz, L, D, C):
    """D (m, 5), C (m, 3) of the module doc at m points: the polynomials in u of d·n,
    d·e_r(x₀), d·e_r(y), d·e_z and sin²φ = 2u − u², multiplied out and integrated against
    L_{n,5}; × 3r/4π."""
    for i in prange(r.shape[0]):
        c = 3.0 * r[i] / (4.0 * np.pi)
        dn0, dn1 = nr[i] * dr[i] + nz[i] * dz[i], -nr[i] * r0[i]
        r0_, r_, dr_, dz_ = r0[i], r[i], dr[i], dz[i]
        rdn = _mul21(dr_, r_, dn0, dn1)               # (d·e_r(x₀)) (d·n)
        zdn = _mul21(dz_, 0.0, dn0, dn1)              # (d·e_z) (d·n)
        Li = L[i]
        D[i, 0] = c * _moment5(Li, _mul31(rdn[0], rdn[1], rdn[2], dr_, -r0_))
        D[i, 1] = c * _moment5(Li, _mul31(rdn[0], rdn[1], rdn[2], dz_, 0.0))
        D[i, 2] = c * _moment5(Li, _mul31(zdn[0], zdn[1], zdn[2], dr_, -r0_))
        D[i, 3] = c * _moment5(Li, _mul31(zdn[0], zdn[1], zdn[2], dz_, 0.0))
        s2dn = _moment5(Li, _mul31(0.0, 2.0, -1.0, dn0, dn1))
        D[i, 4] = c * r_ * r0_ * s2dn
        C[i, 0] = c * _moment5(Li, _mul31(rdn[0], rdn[1], rdn[2], dr_, r_))
        C[i, 1] = c * _moment5(Li, _mul31(zdn[0], zdn[1], zdn[2], dr_, r_))
        C[i, 2] = c * r_ ** 2 * s2dn


def double_layer(x0, y, normal):
    """(D_rr, D_rz, D_zr, D_zz, D_φφ) at x₀ of the ring through y with unit normal ``normal``
    (…, 2) as (n_r, n_z) at y; (…, 5), units 1/length (module doc; × r, without dℓ)."""
    return double_layer_and_constant(x0, y, normal)[0]


def double_layer_constant(x0, y, normal):
    """(C_rr, C_zr, C_φφ): the double layer at x₀ of the constant Cartesian densities e_x (the
    radial direction at x₀) and e_y (its azimuthal direction) carried round the ring through y
    — columns r→r, r→z, φ→φ; the e_z density is D_rz, D_zz of :func:`double_layer`. (…, 3),
    1/length."""
    return double_layer_and_constant(x0, y, normal)[1]


def double_layer_and_constant(x0, y, normal):
    """(:func:`double_layer`, :func:`double_layer_constant`) from one set of moments."""
    r0, r, dr, dz, L = _geometry(x0, y)
    normal = np.asarray(normal, dtype=np.float64)
    shape = np.broadcast_shapes(dr.shape, dz.shape, normal.shape[:-1])
    flat = [np.ascontiguousarray(np.broadcast_to(a, shape), dtype=np.float64).ravel()
            for a in (r0, r, dr, dz, normal[..., 0], normal[..., 1])]
    L = np.ascontiguousarray(np.broadcast_to(L, shape + L.shape[-1:])).reshape(-1, L.shape[-1])
    D, C = np.empty((len(flat[0]), 5)), np.empty((len(flat[0]), 3))
    _double_layer_kernel(*flat, L, D, C)
    return D.reshape(shape + (5,)), C.reshape(shape + (3,))
