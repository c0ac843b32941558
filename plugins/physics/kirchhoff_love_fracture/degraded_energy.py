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
    """½ jetᵀ H₀ jet of ``base`` (see module doc); one density part, ``elastic``.

    H₀ does not depend on the displacement: it is evaluated once per quadrature, as the
    point data (m, n_jet²), so that a staggered solve, which assembles the tangent and the
    densities at every iteration, does not re-evaluate the base energy's Hessian."""

    density_names = ("elastic",)

    def __init__(self, base):
        self.base = base
        self.fields = base.fields
        self.frame_invariant = False   # invariant only under infinitesimal rigid motions
        self.n_jet = sum(f.jet_size for f in base.fields)
        self._cache = None             # (quadrature, its H₀ (m, n_jet²))

    def point_data(self, q) -> np.ndarray:
        if self._cache is None or self._cache[0] is not q:
            data = np.ascontiguousarray(self.base.point_data(q), dtype=np.float64)
            _, _, H0 = self.base.evaluate(np.zeros((len(data), self.n_jet)), data, 2)
            self._cache = (q, np.ascontiguousarray(H0.reshape(len(data), -1)))
        return self._cache[1]

    def evaluate(self, jets, data, want):
        H0 = data.reshape(len(jets), self.n_jet, self.n_jet)
        g = np.einsum("nij,nj->ni", H0, jets)
        dens = 0.5 * np.einsum("ni,ni->n", jets, g)[:, None]
        return dens, (g if want >= 1 else None), (H0 if want >= 2 else None)


class PhaseFieldShellEnergy:
    """The coupled density of both fields, the thesis' Π per area at one point:

        W(u, υ) = (υ² + η) W_shell(u) + G_c h [(1 − υ)²/(4κ̄) + κ̄ a^αβ υ_,α υ_,β],

    jet (displacement jet of the shell, then (υ, υ_,1, υ_,2)), with the full coupled
    gradient and Hessian (∂²W/∂u∂υ = 2υ ∂W_shell/∂u): what a monolithic Newton step and the
    conformance suite's finite-difference check use. Density parts: the shell's parts
    degraded, then ``fracture``."""

    def __init__(self, shell, crack):
        from .phase_field import PHASE_FIELD

        self.shell, self.crack = shell, crack
        self.fields = (*shell.fields, PHASE_FIELD)
        self.density_names = (*shell.density_names, "fracture")
        # the suite's frame invariance is zero energy at a rigid motion with the other fields
        # zero; υ = 0 costs crack energy, so it does not apply (the shell part is invariant)
        self.frame_invariant = False
        self.n_u = sum(f.jet_size for f in shell.fields)

    def point_data(self, q) -> np.ndarray:
        self.crack.driving = None          # the shell energy itself drives υ here
        return np.column_stack([self.shell.point_data(q), self.crack.point_data(q)])

    def evaluate(self, jets, data, want):
        n, nu = len(jets), self.n_u
        du = np.ascontiguousarray(data[:, :-4])
        dv = np.ascontiguousarray(data[:, -4:])
        Ws, gs, Hs = self.shell.evaluate(np.ascontiguousarray(jets[:, :nu]), du, want)
        Wc, gc, Hc = self.crack.evaluate(np.ascontiguousarray(jets[:, nu:]), dv, want)
        v = jets[:, nu]
        g = v * v + self.crack.eta
        W = np.asarray(Ws).sum(axis=1)
        dens = np.column_stack([np.asarray(Ws) * g[:, None], Wc[:, 0]])
        G = H = None
        if want >= 1:
            G = np.empty((n, nu + 3))
            G[:, :nu] = g[:, None] * gs
            G[:, nu:] = gc
            G[:, nu] += 2.0 * v * W
        if want >= 2:
            H = np.zeros((n, nu + 3, nu + 3))
            H[:, :nu, :nu] = g[:, None, None] * Hs
            H[:, :nu, nu] = H[:, nu, :nu] = 2.0 * v[:, None] * gs
            H[:, nu:, nu:] = Hc
            H[:, nu, nu] += 2.0 * W
        return dens, G, H
