"""St. Venant–Kirchhoff shell material: parameters and the plane-stress elasticity tensor.

Thin-shell hyperelasticity through the thickness h (thesis §4.2, Paper 1 §3, Eq. 9–10):

    W = ∫_Ω ½ [ h C^{αβγδ} ε_αβ ε_γδ + h³/12 C^{αβγδ} κ_αβ κ_γδ ] dΩ_0,

    C^{αβγδ} = E/(1−ν²) [ ν A^{αβ}A^{γδ} + ½(1−ν)(A^{αγ}A^{βδ} + A^{αδ}A^{βγ}) ],

A^{αβ} the inverse of the reference metric A_αβ. In Voigt form on the engineering strain
vector e = (ε_11, ε_22, 2ε_12),  C^{αβγδ} ε_αβ ε_γδ = eᵀ D e with

    D = [[C^{1111}, C^{1122}, C^{1112}],
         [C^{1122}, C^{2222}, C^{2212}],
         [C^{1112}, C^{2212}, C^{1212}]].

Units: E force/length², h length; D has the units of E times (chart length)^-4.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pointatlas.errors import ConfigError

VOIGT_PAIRS = ((0, 0), (1, 1), (0, 1))
"""Tensor index pairs (α, β) of the Voigt components 0, 1, 2 (= 11, 22, 12)."""


@dataclass(frozen=True)
class ShellMaterial:
    """Isotropic St. Venant–Kirchhoff shell.

    young_modulus : E > 0 (force/length²)
    poisson_ratio : ν in (−1, 0.5)
    thickness : h > 0 (length)
    """

    young_modulus: float
    poisson_ratio: float
    thickness: float

    def check(self) -> "ShellMaterial":
        """Raise ConfigError naming the bad value, the valid range and the fix; return self."""
        E, nu, h = self.young_modulus, self.poisson_ratio, self.thickness
        for name, value in (("young_modulus", E), ("poisson_ratio", nu), ("thickness", h)):
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating,
                                                                np.integer)):
                raise ConfigError(f"shell {name} = {value!r} is not a number; give a float.")
            if not np.isfinite(value):
                raise ConfigError(f"shell {name} = {value!r} is not finite; give a finite float.")
        if E <= 0:
            raise ConfigError(f"shell young_modulus = {E!r} is invalid; it must be > 0 "
                              "(force/length², e.g. 1.0 in consistent units).")
        if h <= 0:
            raise ConfigError(f"shell thickness = {h!r} is invalid; it must be > 0 (length, "
                              "small compared with the radii of curvature, e.g. 0.01).")
        if not -1.0 < nu < 0.5:
            raise ConfigError(f"shell poisson_ratio = {nu!r} is invalid; it must lie in "
                              "(-1, 0.5) for a stable isotropic material (e.g. 0.3).")
        return self

    @property
    def bending_rigidity(self) -> float:
        """D = E h³ / (12 (1 − ν²)) (force·length)."""
        return self.young_modulus * self.thickness ** 3 / (12.0 * (1.0 - self.poisson_ratio ** 2))

    @property
    def membrane_rigidity(self) -> float:
        """E h / (1 − ν²) (force/length)."""
        return self.young_modulus * self.thickness / (1.0 - self.poisson_ratio ** 2)


def inverse_metric(metric: np.ndarray) -> np.ndarray:
    """A^{αβ} (…, 2, 2) from the covariant metric A_αβ (…, 2, 2)."""
    A = np.asarray(metric, dtype=np.float64)
    det = A[..., 0, 0] * A[..., 1, 1] - A[..., 0, 1] * A[..., 1, 0]
    inv = np.empty_like(A)
    inv[..., 0, 0] = A[..., 1, 1] / det
    inv[..., 1, 1] = A[..., 0, 0] / det
    inv[..., 0, 1] = -A[..., 0, 1] / det
    inv[..., 1, 0] = -A[..., 1, 0] / det
    return inv


def elasticity_tensor(inv_metric: np.ndarray, young_modulus: float,
                      poisson_ratio: float) -> np.ndarray:
    """C^{αβγδ} (…, 2, 2, 2, 2) of the formula in the module docstring (units of E)."""
    G = np.asarray(inv_metric, dtype=np.float64)
    E, nu = float(young_modulus), float(poisson_ratio)
    t1 = np.einsum("...ab,...cd->...abcd", G, G)
    t2 = np.einsum("...ac,...bd->...abcd", G, G) + np.einsum("...ad,...bc->...abcd", G, G)
    return E / (1.0 - nu ** 2) * (nu * t1 + 0.5 * (1.0 - nu) * t2)


def voigt_elasticity(inv_metric: np.ndarray, young_modulus: float,
                     poisson_ratio: float) -> np.ndarray:
    """D (…, 3, 3) on e = (ε_11, ε_22, 2ε_12) so that C^{αβγδ}ε_αβ ε_γδ = eᵀ D e."""
    C = elasticity_tensor(inv_metric, young_modulus, poisson_ratio)
    D = np.empty(C.shape[:-4] + (3, 3))
    for i, (a, b) in enumerate(VOIGT_PAIRS):
        for j, (c, d) in enumerate(VOIGT_PAIRS):
            D[..., i, j] = C[..., a, b, c, d]
    return D
