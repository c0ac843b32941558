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

Crack models (``crack_model``). Both are G_c h/c_w [w(d)/ℓ + ℓ|∇υ|²] in the damage
d = 1 − υ with ℓ = 2κ̄ (Pham, Amor, Marigo & Maurini, Int. J. Damage Mech. 20 (2011) 618;
Tanné, Li, Bourdin, Marigo & Maurini, J. Mech. Phys. Solids 110 (2018) 80):

* ``at2`` (the thesis' model above): w = d², c_w = 2. No elastic phase: any ψ > 0 lowers
  υ, homogeneously to υ = c/(c + 2ψ), c = G_c h/(2κ̄).
* ``at1``: w = d, c_w = 8/3, i.e. G_c h [3(1 − υ)/(16κ̄) + (3κ̄/4)|∇υ|²]. It has an
  elastic threshold: the homogeneous state stays intact (υ = 1) while ψ ≤ ψ_c =
  3G_c h/(32κ̄), and is υ = ψ_c/ψ beyond (stationarity 2υψ = 3G_c h/(16κ̄)). Its band
  across a straight crack is compact, υ(x) = 1 − (1 − |x|/(4κ̄))² for |x| < 4κ̄ and 1
  beyond, with energy G_c h per unit length exactly. The linear term pushes υ above 1
  unless bounded: the bound υ ≤ υ_prev ≤ 1 of the phase step (:mod:`.phase_solve`) is what
  keeps it at 1, so ``at1`` needs that bounded solve, which every scheme here uses.
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np

from pointatlas_kit.fields import Field

#: the crack models (module doc) as (a, b, w quadratic): the density is
#: G_c h [a w(1 − υ)/κ̄ + b κ̄ |∇υ|²] with w(d) = d² (at2) or d (at1)
CRACK_MODELS = {"at2": (0.25, 1.0, True), "at1": (3.0 / 16.0, 0.75, False)}

PHASE_FIELD = Field("phase_field", components=1, order=1, value=True, units="1",
                    long_name="phase field (1 intact, 0 broken)")


class CrackEnergy:
    """W_υ of the module doc (``model`` at2 or at1); jet (υ, υ_,1, υ_,2); point data
    (a^11, a^12, a^22, ψ)."""

    fields: ClassVar[tuple] = (PHASE_FIELD,)
    density_names: ClassVar[tuple] = ("fracture", "degraded_elastic")
    frame_invariant: ClassVar[bool] = False

    def __init__(self, toughness: float, thickness: float, length_scale: float,
                 residual_stiffness: float, driving=None, model: str = "at2"):
        self.Gh = float(toughness) * float(thickness)
        self.kappa = float(length_scale)
        self.eta = float(residual_stiffness)
        self.driving = driving           # (m,) ψ at the quadrature points, or None (ψ = 0)
        self.model = model
        self._a, self._b, self._quadratic = CRACK_MODELS[model]

    def threshold(self) -> float:
        """ψ_c (energy/length²): the driving density below which a homogeneous state stays
        intact; 0 for at2 (no elastic phase), 3G_c h/(32κ̄) for at1 (module doc)."""
        return 0.0 if self._quadratic else self._a * self.Gh / (2.0 * self.kappa)

    def point_data(self, q) -> np.ndarray:
        A = q.inverse_metric
        psi = np.zeros(q.n_points) if self.driving is None else \
            np.asarray(self.driving, dtype=np.float64).reshape(q.n_points)
        return np.column_stack([A[:, 0, 0], A[:, 0, 1], A[:, 1, 1], psi])

    def evaluate(self, jets, data, want):
        v, v1, v2 = jets.T
        a11, a12, a22, psi = data.T
        Gh, k = self.Gh, self.kappa
        a, b = Gh * self._a / k, Gh * self._b * k       # G_c h a/κ̄, G_c h b κ̄
        f1, f2 = a11 * v1 + a12 * v2, a12 * v1 + a22 * v2
        d = 1.0 - v
        w, dw, ddw = (d * d, -2.0 * d, 2.0) if self._quadratic else (d, -1.0, 0.0)
        dens = np.column_stack([a * w + b * (v1 * f1 + v2 * f2), (v * v + self.eta) * psi])
        g = H = None
        if want >= 1:
            g = np.column_stack([a * dw + 2.0 * psi * v, 2.0 * b * f1, 2.0 * b * f2])
        if want >= 2:
            H = np.zeros((len(v), 3, 3))
            H[:, 0, 0] = a * ddw + 2.0 * psi
            H[:, 1, 1], H[:, 2, 2] = 2.0 * b * a11, 2.0 * b * a22
            H[:, 1, 2] = H[:, 2, 1] = 2.0 * b * a12
        return dens, g, H


def degradation(v, residual_stiffness: float):
    """g(υ) = υ² + η_κ̄ (thesis' degradation; 1 + η_κ̄ intact, η_κ̄ broken)."""
    v = np.asarray(v, dtype=np.float64)
    return v * v + float(residual_stiffness)
