"""The tension–compression split of the linear shell energy through the thickness (Amor).

Amor, Marigo & Maurini, J. Mech. Phys. Solids 57 (2009) 1209–1229 split the strain energy
into a volumetric-compressive part, kept intact, and the rest, degraded; Kiendl, Ambati,
De Lorenzis, Gomez & Reali, CMAME 312 (2016) 374–394 §3 argue that for shells the split must
be applied to the strain at points through the thickness, not to the membrane and bending
resultants: a bent shell is in tension on one face and in compression on the other, and only
the tensile side should drive the crack. Here, with the linear Kirchhoff–Love kinematics of
:mod:`pointatlas_physics.kirchhoff_love.linear` (membrane strain e = M U, bending strain
k = B U, Voigt (11, 22, 2·12) in chart coordinates), the strain at the height ζ ∈ [−h/2, h/2]
above the mid-surface is

    ε(ζ) = e + ζ k,

and, in plane stress with the 2-d bulk modulus K = E / (2(1 − ν)) and shear modulus
μ = E / (2(1 + ν)) (tr ε = a^αβ ε_αβ, dev ε = ε − ½ tr ε a, |·|² in the metric a),

    ψ⁺(ε) = K/2 ⟨tr ε⟩₊² + μ |dev ε|²,    ψ⁻(ε) = K/2 ⟨tr ε⟩₋²,

    W(U, υ) = Σ_z w_z [ g(υ) ψ⁺(ε(ζ_z)) + ψ⁻(ε(ζ_z)) ]    (energy per reference area),

with n_z Gauss–Legendre points ζ_z, weights w_z summing to h. Without the split
(ψ⁺ + ψ⁻ = ½ εᵀ D ε, the plane-stress energy) the rule integrates exactly to the shell's
½ h eᵀ D e + ½ h³/12 kᵀ D k; with it, ψ± are piecewise quadratic in ζ and n_z ≥ 5 is used.
The crack is driven by the undegraded tensile part Σ_z w_z ψ⁺ (the phase field is constant
through the thickness, so the two faces share one υ). Under uniaxial compression ψ⁺ is the
deviatoric part only, (1 + ν)/2 of W: the split slows, but does not forbid, shear-driven
damage in compression (Amor et al. §4; Kiendl et al. §3.2).

A kit energy over the shell's ``displacement`` field (the jet of
:mod:`pointatlas_physics.kirchhoff_love.shell_energy`), density parts ``degraded_tensile``
(g ψ⁺ integrated) and ``compressive`` (ψ⁻). It is convex and piecewise quadratic in U and
homogeneous of degree two, so its gradient is its Hessian times U on each piece: the
displacement step (:mod:`.staggered`) is a semi-smooth Newton iteration on the pieces.
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np
from numba import njit

from pointatlas_physics.kirchhoff_love.displacement_field import DISPLACEMENT
from pointatlas_physics.kirchhoff_love.point_kernels import (contravariant_metric,
                                                             strain_jacobians_point)

DENSITY_NAMES = ("degraded_tensile", "compressive")


@njit(cache=True, nogil=True)
def _metric_forms(Y, t, Pd):
    """t (3,) with tr ε = t·e, Pd (3, 3) with |dev ε|² = eᵀ Pd e (Voigt e, metric of Y)."""
    G = contravariant_metric(Y)
    t[0], t[1], t[2] = G[0, 0], G[1, 1], G[0, 1]
    pa = (0, 1, 0)
    pb = (0, 1, 1)
    for i in range(3):
        for j in range(3):
            a, b, c, d = pa[i], pb[i], pa[j], pb[j]
            Pd[i, j] = 0.5 * (G[a, c] * G[b, d] + G[a, d] * G[b, c]) - 0.5 * t[i] * t[j]


@njit(cache=True, nogil=True)
def _amor_points(jets, data, E, nu, zs, ws, want, dens, grad, H):
    K2 = E / (2.0 * (1.0 - nu))
    mu = E / (2.0 * (1.0 + nu))
    Y = np.empty((5, 3))
    Je = np.empty((3, 15))
    Jk = np.empty((3, 15))
    t = np.empty(3)
    Pd = np.empty((3, 3))
    a = np.empty(3)
    b = np.empty(3)
    ez = np.empty(3)
    sz = np.empty(3)
    da = np.empty(3)
    db = np.empty(3)
    C0 = np.empty((3, 3))
    C1 = np.empty((3, 3))
    C2 = np.empty((3, 3))
    for k in range(jets.shape[0]):
        g = data[k, 0]
        for s in range(5):
            for i in range(3):
                Y[s, i] = data[k, 1 + 3 * s + i]
        strain_jacobians_point(Y, Je, Jk)
        _metric_forms(Y, t, Pd)
        for r in range(3):
            a[r] = 0.0
            b[r] = 0.0
            for c in range(15):
                a[r] += Je[r, c] * jets[k, c]
                b[r] += Jk[r, c] * jets[k, c]
        wp = 0.0
        wm = 0.0
        da[:] = 0.0
        db[:] = 0.0
        C0[:, :] = 0.0
        C1[:, :] = 0.0
        C2[:, :] = 0.0
        for iz in range(zs.shape[0]):
            z, w = zs[iz], ws[iz]
            for r in range(3):
                ez[r] = a[r] + z * b[r]
            tr = t[0] * ez[0] + t[1] * ez[1] + t[2] * ez[2]
            dev2 = 0.0
            for r in range(3):
                for c in range(3):
                    dev2 += ez[r] * Pd[r, c] * ez[c]
            tension = tr > 0.0
            vol = 0.5 * K2 * tr * tr
            wp += w * (mu * dev2 + (vol if tension else 0.0))
            wm += w * (0.0 if tension else vol)
            if want >= 1:
                cv = g * K2 * tr if tension else K2 * tr
                for r in range(3):
                    sz[r] = cv * t[r]
                    for c in range(3):
                        sz[r] += 2.0 * g * mu * Pd[r, c] * ez[c]
                    da[r] += w * sz[r]
                    db[r] += w * z * sz[r]
            if want >= 2:
                cv = g * K2 if tension else K2
                for r in range(3):
                    for c in range(3):
                        cc = cv * t[r] * t[c] + 2.0 * g * mu * Pd[r, c]
                        C0[r, c] += w * cc
                        C1[r, c] += w * z * cc
                        C2[r, c] += w * z * z * cc
        dens[k, 0] = g * wp
        dens[k, 1] = wm
        if want >= 1:
            for c in range(15):
                s = 0.0
                for r in range(3):
                    s += Je[r, c] * da[r] + Jk[r, c] * db[r]
                grad[k, c] = s
        if want >= 2:
            for p in range(15):
                for q in range(15):
                    s = 0.0
                    for r in range(3):
                        for c in range(3):
                            s += (Je[r, p] * (C0[r, c] * Je[c, q] + C1[r, c] * Jk[c, q])
                                  + Jk[r, p] * (C1[r, c] * Je[c, q] + C2[r, c] * Jk[c, q]))
                    H[k, p, q] = s


class AmorSplitShellEnergy:
    """g(υ) ψ⁺ + ψ⁻ through the thickness of the linear shell (module doc); ``degradation``
    (m,) at the quadrature points as :class:`.degraded_energy.DegradedEnergy`, None = 1."""

    fields: ClassVar[tuple] = (DISPLACEMENT,)
    density_names: ClassVar[tuple] = DENSITY_NAMES
    frame_invariant: ClassVar[bool] = False   # linear kinematics: infinitesimal motions only

    def __init__(self, young_modulus: float, poisson_ratio: float, thickness: float,
                 thickness_points: int = 5, degradation=None):
        self.E, self.nu, self.h = float(young_modulus), float(poisson_ratio), float(thickness)
        x, w = np.polynomial.legendre.leggauss(int(thickness_points))
        self.zs = 0.5 * self.h * x
        self.ws = 0.5 * self.h * w
        self.degradation = degradation

    def point_data(self, q) -> np.ndarray:
        """(m, 16): g, then the reference jet Y (15) of every point."""
        g = np.ones(q.n_points) if self.degradation is None else \
            np.asarray(self.degradation, dtype=np.float64).reshape(q.n_points)
        return np.column_stack([g, q.reference_jet().reshape(q.n_points, 15)])

    def evaluate(self, jets, data, want):
        n = len(jets)
        dens = np.empty((n, 2))
        g = np.empty((n, 15)) if want >= 1 else np.empty((0, 15))
        H = np.empty((n, 15, 15)) if want >= 2 else np.empty((0, 15, 15))
        _amor_points(np.ascontiguousarray(jets, dtype=np.float64),
                     np.ascontiguousarray(data, dtype=np.float64), self.E, self.nu, self.zs,
                     self.ws, int(want), dens, g, H)
        return dens, (g if want >= 1 else None), (H if want >= 2 else None)

    @staticmethod
    def driving(dens: np.ndarray, g: np.ndarray) -> np.ndarray:
        """The undegraded tensile density Σ_z w_z ψ⁺ (m,) from the densities at degradation g."""
        return dens[:, 0] / g
