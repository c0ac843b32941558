"""The discrete elastic body: mesh, material, clamps, gravity; its energies and forces.

Lagrangian of the full model (Millán 2012 §5.1, Eq. before (5))::

    L(x, ẋ) = ½ ẋᵀ M ẋ − V(x),   V(x) = V_el(x) − f_extᵀ (x − X),

with V_el the neo-Hookean energy of :mod:`.energy`, X the reference positions and
f_ext,a = m_a g the nodal weights (m_a the lumped nodal masses, which equal ∫ ρ N_a dA, so
the load is the consistent one of a uniform body force ρ g). All energies are per unit
thickness (energy / length); g in length / time².

:class:`ElasticBody` is the protocol a reduced model (issue 21) needs of the full one:
``potential_energy(x)``, ``forces(x)`` (= −∂V/∂x on the free DOFs), ``tangent(x)`` and
``mass(kind)``.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from . import energy
from .mesh import TriangleMesh


@dataclass(frozen=True, eq=False)
class ElasticBody:
    """``mesh`` (reference), Lamé λ and μ (force / length²), ``density`` ρ
    (mass / length³), ``gravity`` g (2,), length / time², ``clamped`` (n,) boolean mask."""

    mesh: TriangleMesh
    lam: float
    mu: float
    density: float
    gravity: np.ndarray
    clamped: np.ndarray

    @cached_property
    def _shape(self):
        return energy.reference_gradients(self.mesh.nodes, self.mesh.triangles)

    @property
    def reference(self) -> np.ndarray:
        """Reference positions X (n, 2), length."""
        return self.mesh.nodes

    @property
    def free(self) -> np.ndarray:
        return ~self.clamped

    @cached_property
    def free_dofs(self) -> np.ndarray:
        """Indices 2a + i of the free DOFs."""
        return np.flatnonzero(np.repeat(self.free, 2))

    @cached_property
    def nodal_masses(self) -> np.ndarray:
        """Lumped nodal masses m_a (n,), mass / length."""
        from .mass import lumped_masses

        G, area = self._shape
        return lumped_masses(self.mesh.triangles, area, self.density, self.mesh.n_nodes)

    @cached_property
    def external_forces(self) -> np.ndarray:
        """f_ext,a = m_a g (n, 2), force / length (the clamped nodes' are carried by the
        clamp)."""
        return self.nodal_masses[:, None] * np.asarray(self.gravity, float)[None, :]

    def mass(self, kind: str = "lumped"):
        """:class:`~.mass.Mass` of ``kind`` ('lumped' or 'consistent') on the free nodes."""
        from .mass import Mass

        G, area = self._shape
        return Mass(kind, self.mesh.triangles, area, self.density, self.free)

    # -- energies and forces ------------------------------------------------------------
    def elastic_energy(self, x: np.ndarray) -> float:
        """V_el(x) = Σ_e A_e W(F_e) (+∞ if a triangle is inverted)."""
        G, area = self._shape
        return float(energy.elastic_energy(np.ascontiguousarray(x, float), self.mesh.triangles,
                                           G, area, self.lam, self.mu))

    def gravity_energy(self, x: np.ndarray) -> float:
        """V_g(x) = −f_extᵀ (x − X) (zero in the reference configuration)."""
        return -float(np.sum(self.external_forces * (x - self.reference)))

    def potential_energy(self, x: np.ndarray) -> float:
        """V(x) = V_el(x) + V_g(x)."""
        return self.elastic_energy(x) + self.gravity_energy(x)

    def internal_forces(self, x: np.ndarray, out: np.ndarray | None = None):
        """(f_int = ∂V_el/∂x (n, 2), smallest J); f_int is not meaningful if J ≤ 0."""
        G, area = self._shape
        out = np.empty((self.mesh.n_nodes, 2)) if out is None else out
        jmin = energy.internal_forces(np.ascontiguousarray(x, float), self.mesh.triangles, G,
                                      area, self.lam, self.mu, out)
        return out, float(jmin)

    def forces(self, x: np.ndarray) -> np.ndarray:
        """Net force −∂V/∂x = f_ext − f_int (n, 2), zero on the clamped nodes."""
        f, _ = self.internal_forces(x)
        r = self.external_forces - f
        r[self.clamped] = 0.0
        return r

    def tangent(self, x: np.ndarray):
        """K = ∂²V/∂x² = ∂f_int/∂x, sparse (2n × 2n), all DOFs (restrict to free_dofs)."""
        G, area = self._shape
        return energy.tangent_stiffness(np.ascontiguousarray(x, float), self.mesh.triangles, G,
                                        area, self.lam, self.mu)

    def kernel_arrays(self):
        """(triangles, G, A, λ, μ): the arguments of the :mod:`.energy` kernels."""
        G, area = self._shape
        return self.mesh.triangles, G, area, float(self.lam), float(self.mu)
