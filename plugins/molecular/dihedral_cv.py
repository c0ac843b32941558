"""A dihedral angle as a collective variable, with its analytic gradient (radians, 1/nm).

φ of atoms (i, j, k, l) in the IUPAC convention (as :func:`.engine.dihedrals`), and ∂φ/∂r
by Blondel & Karplus, J. Comput. Chem. 17 (1996) 1132, Eq. (27): with F = r_i − r_j,
G = r_j − r_k, H = r_l − r_k, A = F × G, B = H × G,

    ∂φ/∂r_i = −|G|/|A|² A,    ∂φ/∂r_l = |G|/|B|² B,
    ∂φ/∂r_j = |G|/|A|² A + (F·G)/(|A|²|G|) A − (H·G)/(|B|²|G|) B,
    ∂φ/∂r_k = −|G|/|B|² B − (F·G)/(|A|²|G|) A + (H·G)/(|B|²|G|) B.

Same call interface as :class:`.sandcv.SandCV` (``cv(x, start)`` → a value with ``xi``,
``gradient``, ``ok``), so the biased-MD driver takes either; periodic with period 2π.
:class:`DihedralPairCV` is two of them, e.g. (φ, ψ).
"""
from __future__ import annotations

import numpy as np

from .sandcv import CVValue


class DihedralCV:
    """φ of the four atoms ``atoms`` (indices into the system)."""

    dim = 1
    period = 2.0 * np.pi

    def __init__(self, atoms):
        self.atoms = np.asarray(atoms, dtype=int)
        if self.atoms.shape != (4,):
            raise ValueError("a dihedral needs four atom indices")

    def __call__(self, x, xi_start=None) -> CVValue:
        """φ and ∂φ/∂r of the four atoms' positions x (4, 3) in nm."""
        ri, rj, rk, rl = np.asarray(x, dtype=np.float64)
        F, G, H = ri - rj, rj - rk, rl - rk
        A, B = np.cross(F, G), np.cross(H, G)
        a2, b2, g = A @ A, B @ B, np.sqrt(G @ G)
        phi = np.arctan2((np.cross(B, A) @ G) / g, A @ B)
        grad = np.empty((1, 4, 3))
        fg, hg = F @ G, H @ G
        grad[0, 0] = -g / a2 * A
        grad[0, 3] = g / b2 * B
        grad[0, 1] = g / a2 * A + fg / (a2 * g) * A - hg / (b2 * g) * B
        grad[0, 2] = -g / b2 * B - fg / (a2 * g) * A + hg / (b2 * g) * B
        return CVValue(np.array([phi]), grad, 0.0, 0, 0, 1.0)


class DihedralPairCV:
    """(φ, ψ) of two dihedrals sharing atoms, e.g. the backbone of alanine dipeptide:
    ``atoms`` the union of their atoms (the CV atoms, in this order), ``first`` and
    ``second`` the four positions of each dihedral within ``atoms``."""

    dim = 2
    period = 2.0 * np.pi

    def __init__(self, atoms, first, second):
        self.atoms = np.asarray(atoms, dtype=int)
        self.parts = (np.asarray(first, dtype=int), np.asarray(second, dtype=int))
        self._one = DihedralCV(np.arange(4))

    @classmethod
    def of(cls, quad1, quad2):
        """The pair of dihedrals given by system atom indices (quad1, quad2)."""
        atoms = np.array(sorted(set(quad1) | set(quad2)))
        pos = {a: i for i, a in enumerate(atoms)}
        return cls(atoms, [pos[a] for a in quad1], [pos[a] for a in quad2])

    def __call__(self, x, xi_start=None) -> CVValue:
        x = np.asarray(x, dtype=np.float64)
        xi = np.empty(2)
        grad = np.zeros((2, len(self.atoms), 3))
        for k, part in enumerate(self.parts):
            v = self._one(x[part])
            xi[k] = v.xi[0]
            grad[k, part] = v.gradient[0]
        return CVValue(xi, grad, 0.0, 0, 0, 1.0)
