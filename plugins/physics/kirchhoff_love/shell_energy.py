"""The Kirchhoff–Love shell energy as a kit energy (St. Venant–Kirchhoff, thesis §4.2).

Field ``displacement`` (3 components, chart derivatives to order 2, value unused). The jet
at a point is δy = Σ_a (p_a,1, p_a,2, p_a,11, p_a,12, p_a,22) U_a (15 entries, y[3k + i] as
in :mod:`.point_kernels`); the kernel adds the reference Y = (X_,1, X_,2, X_,11, X_,12,
X_,22) kept as point data and evaluates

    w(y) = ½ h eᵀ D e + ½ h³/12 kᵀ D k    (membrane, bending; energy per reference area)

with its gradient and Hessian in y (Paper 1 App. B–C, Paper 2 §2; formulas in
:mod:`.point_kernels`). Rigid motions leave w unchanged (Green strain, exact normal).
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np
from numba import njit

from .displacement_field import DISPLACEMENT
from .point_kernels import gradient_hessian_point, voigt_elasticity_point


@njit(cache=True, nogil=True)
def _shell_points(jets, data, E, nu, h, want, dens, g, H):
    y = np.empty((5, 3))
    Y = np.empty((5, 3))
    D = np.empty((3, 3))
    gq = np.empty(15)
    Hq = np.empty((15, 15)) if want >= 2 else np.empty((1, 1))
    for k in range(jets.shape[0]):
        for s in range(5):
            for i in range(3):
                Y[s, i] = data[k, 3 * s + i]
                y[s, i] = Y[s, i] + jets[k, 3 * s + i]
        voigt_elasticity_point(Y, E, nu, D)
        wm, wb = gradient_hessian_point(y, Y, D, h, gq, Hq, want >= 2)
        dens[k, 0] = wm
        dens[k, 1] = wb
        if want >= 1:
            for r in range(15):
                g[k, r] = gq[r]
        if want >= 2:
            for r in range(15):
                for s in range(15):
                    H[k, r, s] = Hq[r, s]


class ShellEnergy:
    """Membrane + bending energy of a Kirchhoff–Love shell of thickness h (length), Young's
    modulus E (force/length²) and Poisson ratio ν."""

    fields: ClassVar[tuple] = (DISPLACEMENT,)
    density_names: ClassVar[tuple] = ("membrane", "bending")
    frame_invariant: ClassVar[bool] = True

    def __init__(self, young_modulus: float, poisson_ratio: float, thickness: float):
        self.E, self.nu, self.h = float(young_modulus), float(poisson_ratio), float(thickness)

    def point_data(self, quadrature) -> np.ndarray:
        """(m, 15) the reference Y of every point."""
        return quadrature.reference_jet().reshape(quadrature.n_points, 15)

    def evaluate(self, jets, data, want):
        n = len(jets)
        dens = np.empty((n, 2))
        g = np.empty((n, 15)) if want >= 1 else np.empty((0, 15))
        H = np.empty((n, 15, 15)) if want >= 2 else np.empty((0, 15, 15))
        _shell_points(np.ascontiguousarray(jets), np.ascontiguousarray(data), self.E, self.nu,
                      self.h, int(want), dens, g, H)
        return dens, (g if want >= 1 else None), (H if want >= 2 else None)
