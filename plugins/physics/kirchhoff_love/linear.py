"""Linear Kirchhoff–Love shell stiffness from strain–displacement matrices (Paper 1 App. B–C).

Linearizing the strains of point_kernels about the reference configuration (U = 0), with
t_0 = X_,1 × X_,2 / j̄_0 the reference normal and u_,α = Σ_a p_a,α U_a:

    δe = Σ_a M_a U_a,   M_a rows: p_a,1 X_,1;  p_a,2 X_,2;  p_a,2 X_,1 + p_a,1 X_,2,
    δk = Σ_a B_a U_a,   B_a row of κ_αβ (factor 2 for αβ = 12):
        −[ p_a,αβ t_0 + j̄_0⁻¹ ( p_a,1 X_,2 × r_αβ + p_a,2 r_αβ × X_,1 ) ],
        r_αβ = X_,αβ − (X_,αβ · t_0) t_0,

which is Paper 1 Eq. (B2)/App. C rewritten with a·(b×c) = b·(c×a). The stiffness is

    K_ab = Σ_q w_q [ h M_aᵀ D M_b + h³/12 B_aᵀ D B_b ]   (force/length, DOFs 3a + i),

equal to the tangent ∂²W/∂U² of nonlinear.py at U = 0. Rigid translations and infinitesimal
rotations U_a = ω × P_a are in its null space when X = Σ p_a P_a (linear reproduction).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .material import ShellMaterial
from .point_kernels import strain_jacobians_point


@njit(cache=True, nogil=True)
def _strain_displacement_kernel(indptr, basis, reference, M, B):
    m = len(indptr) - 1
    for q in range(m):
        Je = np.empty((3, 15))
        Jk = np.empty((3, 15))
        strain_jacobians_point(reference[q], Je, Jk)
        for t in range(indptr[q], indptr[q + 1]):
            for r in range(3):
                for i in range(3):
                    sm = 0.0
                    sb = 0.0
                    for kk in range(5):
                        sm += basis[t, kk + 1] * Je[r, 3 * kk + i]
                        sb += basis[t, kk + 1] * Jk[r, 3 * kk + i]
                    M[t, r, i] = sm
                    B[t, r, i] = sb


def strain_displacement_matrices(q) -> tuple[np.ndarray, np.ndarray]:
    """(M, B), each (nnz, 3, 3): membrane and bending strain–displacement matrices per entry.

    Entry t of the CSR layout (point q, node a = q.indices[t]) gives M_a, B_a at point q, rows
    the Voigt components (11, 22, 2·12), columns the displacement components x, y, z.
    Units: M dimensionless (chart units), B 1/length.
    """
    nnz = len(q.indices)
    M = np.empty((nnz, 3, 3))
    B = np.empty((nnz, 3, 3))
    _strain_displacement_kernel(q.indptr, q.basis, q.reference_jet(), M, B)
    return M, B


def linear_stiffness(q, mat: ShellMaterial):
    """K (3N, 3N) scipy.sparse.csr_matrix, symmetric, force/length (equation in module doc):
    the tangent of the kit's shell energy at U = 0 (:mod:`.nonlinear`)."""
    from .nonlinear import tangent_stiffness

    return tangent_stiffness(q, mat, np.zeros((q.n_nodes, 3)))
