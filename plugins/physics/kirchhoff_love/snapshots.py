"""Energy density of a shell at its sampled points (the operator behind the snapshots).

Thesis Fig. 16 and Fig. 18 (§4.4, Paper 2 §5) show snapshots of a shell along its load path,
the deformed points (not magnified) coloured by the strain energy density. Here

    w(x_a) = w_m + w_b,   w_m = ½ h eᵀ D e,   w_b = ½ h³/12 kᵀ D k     (energy/length²)

per unit reference area, evaluated with the geometrically exact kinematics of nonlinear.py
(Green membrane strain e, bending strain k = B − b; point_kernels.py, thesis §4.2) at every
sampled point x_a itself: each point is evaluated in its best chart (largest ψ_κ, see
pointatlas_atlas.evaluation.node_charts) at its own embedded coordinates ξ_a = Ξ_κ[a], with
the reference derivatives X_,α, X_,αβ of that chart φ_κ = Σ p_b C_b (as the quadrature of
build_model does). A rigid motion gives w = 0.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


from .material import ShellMaterial

DENSITY_COLUMNS = ("membrane", "bending", "total")
"""Columns of the array returned by PointEnergyOperator (energy per reference area)."""


@dataclass
class PointEnergyOperator:
    """U (N+G, 3) → (n_points, 3) energy density per unit reference area at the sampled points.

    quadrature : AtlasQuadrature whose points are the sampled points with a defined basis
        (unit weights; the weights are not used for densities)
    rows : (m,) output row (sampled point index) of each quadrature point
    n_points : number of sampled points; rows of points where the chart's LME basis is
        undefined (flagged outside the chart; normally none) are NaN
    """

    quadrature: object
    material: ShellMaterial
    rows: np.ndarray
    n_points: int

    @property
    def n_undefined(self) -> int:
        return self.n_points - len(self.rows)

    def __call__(self, U) -> np.ndarray:
        """(n_points, 3) float64: membrane, bending, total (energy/length², e.g. N/m)."""
        from .nonlinear import shell_assembler

        dens = shell_assembler(self.quadrature, self.material).densities(U)
        out = np.full((self.n_points, 3), np.nan)
        out[self.rows, :2] = dens
        out[self.rows, 2] = dens.sum(axis=1)
        return out


def point_energy_operator(model) -> PointEnergyOperator:
    """Build, once, the quadrature at the sampled points of a ShellModel (build_model).

    Basis values, first and second chart derivatives of every sampled point in its best
    chart; reference tangents and second derivatives from that chart's control points
    (thesis Eq. 2, §4.2). Each call of the result is one pass of the numba kernel.
    """
    from pointatlas_kit.atlas_quadrature import node_quadrature

    n_points = model.points.shape[0]
    model.material.check()
    q, rows = node_quadrature(model.atlas, np.arange(n_points), order=2)
    return PointEnergyOperator(q, model.material, rows, n_points)
