"""The phase field υ of a fracturing shell and its regularised crack energy (a kit energy).

Thesis §4 "Ongoing research" (reference L613–640) and Amiri, Millán, Shen, Rabczuk & Arroyo,
Theor. Appl. Fract. Mech. 69 (2014) 102–109, Eq. (6)–(8): υ = 1 intact, υ = 0 broken,
constant through the thickness h, and

    Π[u, υ] = ∫ (υ² + η_κ̄) W(u) dΩ₀ + G_c h ∫ ((1 − υ)²/(4κ̄) + κ̄ |∇υ|²) dΩ₀ + Π_ext[u].

With ℓ = 2κ̄ the crack density is the AT2 functional (1 − υ)²/(2ℓ) + (ℓ/2)|∇υ|² of
Bourdin, Francfort & Marigo (2000) / Miehe et al. (2010) in its usual form. Across a straight
crack (υ = 0 on the line) the minimiser is υ(x) = 1 − exp(−|x|/(2κ̄)) and the crack energy
per unit length is exactly G_c h: the band spans about ±4κ̄ (1 − υ < 0.14).

For a given driving energy density ψ ≥ 0 at each point (the undegraded shell energy W(u) of
the current displacement, energy/length²), :class:`CrackEnergy` is the phase-field part of
Π at fixed u, a quadratic in υ,

    W_υ = G_c h [ (1 − υ)²/(4κ̄) + κ̄ a^αβ υ_,α υ_,β ] + (υ² + η_κ̄) ψ,

with the surface gradient |∇υ|² = a^αβ υ_,α υ_,β in the chart metric. Units: G_c
energy/length² (a toughness, J/m²), h and κ̄ length, W_υ energy/length².
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np

from pointatlas_kit.fields import Field

PHASE_FIELD = Field("phase_field", components=1, order=1, value=True, units="1",
                    long_name="phase field (1 intact, 0 broken)")


class CrackEnergy:
    """W_υ of the module doc; jet (υ, υ_,1, υ_,2); point data (a^11, a^12, a^22, ψ)."""

    fields: ClassVar[tuple] = (PHASE_FIELD,)
    density_names: ClassVar[tuple] = ("fracture", "degraded_elastic")
    frame_invariant: ClassVar[bool] = False

    def __init__(self, toughness: float, thickness: float, length_scale: float,
                 residual_stiffness: float, driving=None):
        self.Gh = float(toughness) * float(thickness)
        self.kappa = float(length_scale)
        self.eta = float(residual_stiffness)
        self.driving = driving           # (m,) ψ at the quadrature points, or None (ψ = 0)

    def point_data(self, q) -> np.ndarray:
        A = q.inverse_metric
        psi = np.zeros(q.n_points) if self.driving is None else \
            np.asarray(self.driving, dtype=np.float64).reshape(q.n_points)
        return np.column_stack([A[:, 0, 0], A[:, 0, 1], A[:, 1, 1], psi])

    def evaluate(self, jets, data, want):
        v, v1, v2 = jets.T
        a11, a12, a22, psi = data.T
        Gh, k = self.Gh, self.kappa
        f1, f2 = a11 * v1 + a12 * v2, a12 * v1 + a22 * v2
        dens = np.column_stack([Gh * ((1.0 - v) ** 2 / (4.0 * k) + k * (v1 * f1 + v2 * f2)),
                                (v * v + self.eta) * psi])
        g = H = None
        if want >= 1:
            g = np.column_stack([-Gh * (1.0 - v) / (2.0 * k) + 2.0 * psi * v,
                                 2.0 * Gh * k * f1, 2.0 * Gh * k * f2])
        if want >= 2:
            H = np.zeros((len(v), 3, 3))
            H[:, 0, 0] = Gh / (2.0 * k) + 2.0 * psi
            H[:, 1, 1], H[:, 2, 2] = 2.0 * Gh * k * a11, 2.0 * Gh * k * a22
            H[:, 1, 2] = H[:, 2, 1] = 2.0 * Gh * k * a12
        return dens, g, H


def degradation(v, residual_stiffness: float):
    """g(υ) = υ² + η_κ̄ (thesis' degradation; 1 + η_κ̄ intact, η_κ̄ broken)."""
    v = np.asarray(v, dtype=np.float64)
    return v * v + float(residual_stiffness)
