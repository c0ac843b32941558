"""Kit energies the fracture physics builds from the shell's: degraded and linearised.

:class:`DegradedEnergy` multiplies any kit energy density by a per-point factor g_q (the
degradation g(υ) = υ² + η_κ̄ of :mod:`.phase_field` at fixed υ, the displacement step of a
staggered solve):  W_g(jet) = g_q W(jet), with its gradient and Hessian scaled alike.

:class:`Linearized` is the second-order expansion of an energy about the reference jet
(jet = 0, a stress-free reference: W(0) = 0, ∂W/∂jet(0) = 0),

    W_lin(jet) = ½ jetᵀ H₀ jet,   H₀ = ∂²W/∂jet²(0),

i.e. the energy of the linear kinematics (for the shell: the quadratic form of its linear
stiffness, :mod:`pointatlas_physics.kirchhoff_love.linear`). Both keep the base energy's
fields and units (energy/length²).
"""
from __future__ import annotations

import numpy as np


class DegradedEnergy:
    """g_q × ``base``; ``degradation`` (m,) at the quadrature points, None = 1 (intact)."""

    def __init__(self, base, degradation=None):
        self.base = base
        self.fields = base.fields
        self.density_names = base.density_names
        self.frame_invariant = base.frame_invariant
        self.degradation = degradation

    def point_data(self, q) -> np.ndarray:
        g = np.ones(q.n_points) if self.degradation is None else \
            np.asarray(self.degradation, dtype=np.float64).reshape(q.n_points)
        return np.column_stack([g, self.base.point_data(q)])

    def evaluate(self, jets, data, want):
        s = data[:, 0]
        dens, g, H = self.base.evaluate(jets, np.ascontiguousarray(data[:, 1:]), want)
        dens = np.asarray(dens) * s[:, None]
        if g is not None:
            g = g * s[:, None]
        if H is not None:
            H = H * s[:, None, None]
        return dens, g, H


class Linearized:
    """½ jetᵀ H₀ jet of ``base`` (see module doc); one density part, ``elastic``."""

    density_names = ("elastic",)

    def __init__(self, base):
        self.base = base
        self.fields = base.fields
        self.frame_invariant = False   # invariant only under infinitesimal rigid motions

    def point_data(self, q) -> np.ndarray:
        return self.base.point_data(q)

    def evaluate(self, jets, data, want):
        _, _, H0 = self.base.evaluate(np.zeros_like(jets), data, 2)
        g = np.einsum("nij,nj->ni", H0, jets)
        dens = 0.5 * np.einsum("ni,ni->n", jets, g)[:, None]
        return dens, (g if want >= 1 else None), (H0 if want >= 2 else None)
