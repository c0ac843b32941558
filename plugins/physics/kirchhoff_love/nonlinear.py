"""Nonlinear (St. Venant–Kirchhoff) shell energy, internal forces and tangent stiffness.

Thesis §4.2, Paper 2 §2 (Eqs. for f_int and K_T, thesis L2557–2780), with

    W(U) = Σ_q w_q w(y_q(U)),   w(y) = ½ h eᵀ D e + ½ h³/12 kᵀ D k   (point_kernels.py),
    y_q = Y_q + Σ_a (p_a,1, p_a,2, p_a,11, p_a,12, p_a,22)(ξ_q) U_a,

so that, with φ_a = (p_a,1, …, p_a,22) (5,) and ⊗ I_3 for the Cartesian components,

    f_a = ∂W/∂U_a = Σ_q w_q Σ_k φ_a,k ∂w/∂y_k,
    K_ab = ∂²W/∂U_a∂U_b = Σ_q w_q Σ_kl φ_a,k φ_b,l ∂²w/∂y_k∂y_l,

assembled by the kit's one assembler (:mod:`pointatlas_kit.assembler`) from the shell
energy kernel (:mod:`.shell_energy`) on an :class:`pointatlas_kit.atlas_quadrature.
AtlasQuadrature`. Units: U length, W energy, f force, K force/length. Membrane energy uses
the Green strain ε_αβ = ½(a_αβ − A_αβ); bending energy uses κ_αβ = B_αβ − b_αβ (exact finite
rotations: a rigid motion has W = 0).
"""
from __future__ import annotations

import numpy as np

from .material import ShellMaterial


def shell_assembler(q, mat: ShellMaterial):
    """The kit :class:`~pointatlas_kit.assembler.Assembler` of the shell energy on ``q``."""
    from pointatlas_kit.assembler import Assembler
    from pointatlas_kit.fields import FieldLayout

    from .shell_energy import DISPLACEMENT, ShellEnergy

    mat.check()
    energy = ShellEnergy(mat.young_modulus, mat.poisson_ratio, mat.thickness)
    return Assembler(q, FieldLayout([DISPLACEMENT], q.n_nodes), [energy])


def energy_density(q, mat: ShellMaterial, U) -> np.ndarray:
    """(m,) membrane + bending energy per unit reference area at each point (energy/length²)."""
    return shell_assembler(q, mat).densities(U).sum(axis=1)


def energy(q, mat: ShellMaterial, U) -> dict[str, float]:
    """{'total', 'membrane', 'bending'}: W = Σ_q w_q w(y_q) and its two parts (energy)."""
    return shell_assembler(q, mat).energy(U)


def internal_forces(q, mat: ShellMaterial, U) -> np.ndarray:
    """(N, 3) f = ∂W/∂U (force); DOF 3a + i is f[a, i]."""
    return shell_assembler(q, mat).residual(U)[1].reshape(-1, 3)


def tangent_stiffness(q, mat: ShellMaterial, U):
    """K_T = ∂²W/∂U² (3N, 3N) scipy.sparse.csr_matrix, symmetric (force/length)."""
    return shell_assembler(q, mat).tangent(U)
