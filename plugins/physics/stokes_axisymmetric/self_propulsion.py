"""One shape of a swimmer: tractions, rigid velocities (V_c, ω) and dissipated powers.

Arroyo, Heltai, Millán & DeSimone, PNAS 109 (2012) 17874, SI Eqs. S10–S11. With the same
surface velocity v inside and out (the "isolated active surface"), adding the interior and
exterior boundary integral equations gives the single-layer (first-kind) equation

    v(x) = (1/8πμ) ∫ M(x, y) f(y) dℓ_y,    f = f_inn + f_out

for the total traction f (force per area exerted by the surface on the fluid). The exterior
equation alone, on the surface, reads

    (1/8πμ) ∫ M f_out dℓ = ½ v − PV ∫ T_ijk v_j n_k dS

(:mod:`.ring_kernels` for the signs). Both use the same single-layer matrix, factorised once.
The single layer annihilates f = c n, so the traction is fixed up to a uniform pressure: a
Lagrange multiplier λ (a normal velocity λ n added to the rows) enforces ∫ f·n dS = 0; with
∫ v·n dS = 0 (the permeation velocity −V̇/S n makes it so) λ vanishes and the gauge changes
neither force, torque nor power.

Free swimming: v = v_s + V_c e_z + ω r e_φ with unknown V_c, ω closed by zero axial force
∫ f_z dS = 0 and zero axial torque ∫ r f_φ dS = 0 (the interior traction exerts neither). By
linearity f = f_s + V_c f_U (f_U the traction of a unit translation), so V_c = −F_s/F_U and
ω = −T_s/T_Ω. Powers W = ∫ f·v dS (power by the surface on the fluid, ≥ 0).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import lu_factor, lu_solve
from threadpoolctl import threadpool_limits

from .boundary_elements import Elements, double_layer_rhs, single_layer_matrices


@dataclass
class ShapeSolution:
    """Per element (n,): traction total f and exterior f_out as (r, z, φ) columns (n, 3),
    the velocity at the collocation points (n, 3); scalars: V_c, ω, axial force and torque on
    the fluid, powers (exterior, interior + exterior), V̇, permeation speed, gauge λ."""

    traction: np.ndarray
    traction_out: np.ndarray
    velocity: np.ndarray
    translation: float
    rotation: float
    force: float
    torque: float
    power_out: float
    power_total: float
    volume_rate: float
    permeation: float
    gauge: float


class SingleLayerSolver:
    """LU factors of the bordered meridional operator and of the swirl operator of ``el``
    for viscosity ``mu`` (Pa·s or any consistent unit)."""

    def __init__(self, el: Elements, mu: float):
        self.el, self.mu = el, float(mu)
        A, B = single_layer_matrices(el)
        A /= 8.0 * np.pi * mu
        B /= 8.0 * np.pi * mu
        n = el.n
        nn = el.n_mid.reshape(-1)                             # λ column: n at x_i
        g = (el.ring_area[:, None] * el.n_mid).reshape(-1)    # ∫ f·n dS row
        self.n = n
        with threadpool_limits(1, "blas"):   # a 400² LU: threads only cost here (120 → 3 ms)
            self.mer = lu_factor(np.block([[A, nn[:, None]], [g[None, :], np.zeros((1, 1))]]))
            self.swirl = lu_factor(B)
        self.unit_translation = self.meridional(np.tile([0.0, 1.0], (n, 1)))[0]
        self.unit_rotation = self.swirling(el.x_mid[:, 0])

    def meridional(self, v):
        """(f (n, 2), λ) for the velocity (v_r, v_z) (n, 2) at the collocation points."""
        x = lu_solve(self.mer, np.append(np.asarray(v, float).reshape(-1), 0.0))
        return x[:-1].reshape(-1, 2), x[-1]

    def swirling(self, v_phi):
        return lu_solve(self.swirl, np.asarray(v_phi, float))

    def axial_force(self, f):
        return float(np.sum(self.el.ring_area * f[:, 1]))

    def axial_torque(self, f_phi):
        return float(np.sum(self.el.ring_moment * f_phi))


def _power(el: Elements, f: np.ndarray, velocity_q: np.ndarray) -> float:
    """∫ f·v dS with f constant per element and v at the quadrature points (n, G, 3)."""
    r = el.x_q[..., 0]
    fv = np.einsum("ek,egk->eg", f, velocity_q)
    return float(2.0 * np.pi * np.sum(fv * r * el.w_q))


def solve_shape(el: Elements, velocity, mu: float, free: bool = True,
                permeation: bool = True, solver: SingleLayerSolver | None = None
                ) -> ShapeSolution:
    """The swimmer (``free``: V_c, ω unknown) or a body moved as prescribed (``free=False``:
    ``velocity`` is the whole surface velocity) for the nodal velocity spline ``velocity``
    (t → (v_r, v_z, v_φ), length/time); module doc."""
    S = solver or SingleLayerSolver(el, mu)
    vq = velocity(el.t_q)                                     # (n, G, 3)
    area = float(el.ring_area.sum())
    r_q = el.x_q[..., 0]
    vdot = float(2.0 * np.pi * np.sum(np.einsum("egk,egk->eg", vq[..., :2], el.n_q)
                                      * r_q * el.w_q))
    w = -vdot / area if permeation else 0.0

    def surface_velocity(t, n_t):
        v = velocity(t)
        v[..., :2] += w * n_t
        return v

    vs_q = vq.copy()
    vs_q[..., :2] += w * el.n_q
    vs_mid = surface_velocity(el.t_mid, el.n_mid)
    f_s, lam = S.meridional(vs_mid[:, :2])
    g_s = S.swirling(vs_mid[:, 2])
    V = -S.axial_force(f_s) / S.axial_force(S.unit_translation) if free else 0.0
    Om = -S.axial_torque(g_s) / S.axial_torque(S.unit_rotation) if free else 0.0
    f = np.column_stack([f_s + V * S.unit_translation, g_s + Om * S.unit_rotation])
    # exterior traction: the double layer of the deformation part, rigid parts as f_U, f_Ω
    rhs = 0.5 * vs_mid - double_layer_rhs(el, lambda t: surface_velocity(
        t, el.meridian.normal(t)))
    fo, _ = S.meridional(rhs[:, :2])
    go = S.swirling(rhs[:, 2])
    f_out = np.column_stack([fo + V * S.unit_translation, go + Om * S.unit_rotation])
    v_q = vs_q.copy()
    v_q[..., 1] += V
    v_q[..., 2] += Om * r_q
    v_mid = vs_mid.copy()
    v_mid[:, 1] += V
    v_mid[:, 2] += Om * el.x_mid[:, 0]
    return ShapeSolution(traction=f, traction_out=f_out, velocity=v_mid, translation=V,
                         rotation=Om, force=S.axial_force(f), torque=S.axial_torque(f[:, 2]),
                         power_out=_power(el, f_out, v_q), power_total=_power(el, f, v_q),
                         volume_rate=vdot, permeation=w, gauge=float(lam))
