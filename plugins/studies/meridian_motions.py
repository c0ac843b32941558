"""Generating curves and surface motions of the Stokes experiments, built from formulas.

Curves are (r, z) nodes from the top pole to the bottom one (polar angle θ ∈ [0, π] from +z,
uniform in θ); velocities are (v_r, v_z, v_φ) at the nodes, in the body frame. e_r = (sin θ,
cos θ) and e_θ = (cos θ, −sin θ) are the spherical unit vectors in the (r, z) plane. Legendre
modes P_n(cos θ) and Blake's tangential modes V_n(θ) = 2 sin θ P_n′(cos θ)/(n(n+1)) (V_1 =
sin θ). Lengths in units of the radius a given, times in those of the period T.
"""
from __future__ import annotations

import numpy as np
from numpy.polynomial import legendre


def polar_angles(n_nodes: int) -> np.ndarray:
    return np.linspace(0.0, np.pi, n_nodes)


def spheroid(radius: float, aspect_ratio: float, n_nodes: int) -> np.ndarray:
    """Nodes of a spheroid with equatorial radius ``radius`` and polar semi-axis
    ``aspect_ratio × radius`` (1: a sphere)."""
    th = polar_angles(n_nodes)
    return np.column_stack([radius * np.sin(th), aspect_ratio * radius * np.cos(th)])


def translation(nodes: np.ndarray, speed: float) -> np.ndarray:
    """Rigid translation along +z."""
    v = np.zeros((len(nodes), 3))
    v[:, 1] = speed
    return v


def rotation(nodes: np.ndarray, angular_velocity: float) -> np.ndarray:
    """Rigid rotation about +z: v_φ = Ω r."""
    v = np.zeros((len(nodes), 3))
    v[:, 2] = angular_velocity * nodes[:, 0]
    return v


def legendre_p(n: int, x):
    return legendre.legval(x, np.eye(n + 1)[n])


def blake_v(n: int, theta):
    """V_n(θ) = 2 sin θ P_n′(cos θ) / (n(n+1))."""
    d = legendre.legder(np.eye(n + 1)[n])
    return 2.0 * np.sin(theta) * legendre.legval(np.cos(theta), d) / (n * (n + 1))


def _spherical_to_rz(theta, v_r, v_t):
    return np.column_stack([v_r * np.sin(theta) + v_t * np.cos(theta),
                            v_r * np.cos(theta) - v_t * np.sin(theta)])


def squirmer_slip(radius: float, n_nodes: int, B1: float, B2: float):
    """(nodes, velocities) of a sphere with tangential slip u_θ = B1 sin θ + B2 sin θ cos θ."""
    th = polar_angles(n_nodes)
    nodes = spheroid(radius, 1.0, n_nodes)
    ut = B1 * np.sin(th) + B2 * np.sin(th) * np.cos(th)
    v = np.zeros((n_nodes, 3))
    v[:, :2] = _spherical_to_rz(th, 0.0 * th, ut)
    return nodes, v


def modal_displacement(theta, radial: dict, tangential: dict):
    """Complex (ξ_r, ξ_θ)/(ε a) of Σ A_n P_n e_r + Σ B_n V_n e_θ at the angles θ."""
    c = np.cos(theta)
    xr = sum(complex(A) * legendre_p(n, c) for n, A in radial.items()) + 0j * theta
    xt = sum(complex(B) * blake_v(n, theta) for n, B in tangential.items()) + 0j * theta
    return xr, xt


def small_amplitude_stroke(radius: float, n_nodes: int, n_phases: int, epsilon: float,
                           radial: dict, tangential: dict):
    """(times (K+1,), shapes, velocities) of material points x(θ, t) = x₀(θ) + ε a
    Re[e^{−iωt}(Σ A_n P_n e_r + Σ B_n V_n e_θ)] over one period T = 1 (ω = 2π)."""
    th = polar_angles(n_nodes)
    x0 = spheroid(radius, 1.0, n_nodes)
    xr, xt = modal_displacement(th, radial, tangential)
    t = np.linspace(0.0, 1.0, n_phases + 1)
    w = 2.0 * np.pi
    ph = np.exp(-1j * w * t)[:, None]
    shapes = x0[None] + epsilon * radius * np.stack([
        _spherical_to_rz(th, (p * xr).real, (p * xt).real) for p in ph[:, 0]])
    vel = np.zeros(shapes.shape[:2] + (3,))
    for k, p in enumerate(ph[:, 0]):
        vel[k, :, :2] = epsilon * radius * _spherical_to_rz(th, (-1j * w * p * xr).real,
                                                           (-1j * w * p * xt).real)
    shapes[:, [0, -1], 0] = 0.0            # the poles stay on the axis
    return t, shapes, vel


def reciprocal_stroke(radius: float, n_nodes: int, n_phases: int, amplitude: float,
                      twist: float, warp: float):
    """(times, shapes, velocities) of a stroke that traces a shape path forward and back at
    different rates: s(t) = (1 − cos 2πτ)/2 with the time warp τ = t + warp sin(2πt)/(2π)
    (|warp| < 1), radial material displacement a s (P_2 + ½ P_3) × ``amplitude`` and a swirl
    v_φ = a ṡ ``twist`` sin θ cos θ (a twist and untwist); T = 1."""
    th = polar_angles(n_nodes)
    x0 = spheroid(radius, 1.0, n_nodes)
    c = np.cos(th)
    g = amplitude * (legendre_p(2, c) + 0.5 * legendre_p(3, c))
    t = np.linspace(0.0, 1.0, n_phases + 1)
    tau = t + warp * np.sin(2 * np.pi * t) / (2 * np.pi)
    dtau = 1.0 + warp * np.cos(2 * np.pi * t)
    s = 0.5 * (1.0 - np.cos(2 * np.pi * tau))
    sdot = np.pi * np.sin(2 * np.pi * tau) * dtau
    e_r = np.column_stack([np.sin(th), np.cos(th)])
    shapes = x0[None] + radius * s[:, None, None] * g[None, :, None] * e_r[None]
    vel = np.zeros(shapes.shape[:2] + (3,))
    vel[:, :, :2] = radius * sdot[:, None, None] * g[None, :, None] * e_r[None]
    vel[:, :, 2] = radius * sdot[:, None] * twist * (np.sin(th) * np.cos(th))[None]
    shapes[:, [0, -1], 0] = 0.0
    return t, shapes, vel, s
