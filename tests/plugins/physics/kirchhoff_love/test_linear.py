import numpy as np
import pytest

from pointatlas_physics.kirchhoff_love.linear import linear_stiffness, strain_displacement_matrices
from pointatlas_physics.kirchhoff_love.nonlinear import tangent_stiffness


def _rel(K, v):
    return np.linalg.norm(K @ v) / (abs(K).max() * np.linalg.norm(v))


def test_symmetric_and_equal_to_tangent_at_zero(cylinder_patch, material):
    q, P = cylinder_patch
    K = linear_stiffness(q, material)
    K0 = tangent_stiffness(q, material, np.zeros((q.n_nodes, 3)))
    scale = abs(K).max()
    assert abs(K - K.T).max() < 1e-12 * scale
    assert abs(K - K0).max() < 1e-10 * scale
    assert K.shape == (3 * q.n_nodes, 3 * q.n_nodes)


def test_rigid_motions_in_null_space(cylinder_patch, material):
    q, P = cylinder_patch
    K = linear_stiffness(q, material)
    for i in range(3):
        t = np.zeros((q.n_nodes, 3))
        t[:, i] = 1.0
        assert _rel(K, t.ravel()) < 1e-10
        omega = np.eye(3)[i]
        assert _rel(K, np.cross(omega, P).ravel()) < 1e-10
    # a genuine deformation is not in the null space (the test can fail)
    bend = np.zeros((q.n_nodes, 3))
    bend[:, 0] = P[:, 2] ** 2
    assert _rel(K, bend.ravel()) > 1e-4


def test_cylindrical_bending_energy_of_flat_plate(material, make_polynomial_plate):
    """u_z = ½ c x² on the unit square: ½ Uᵀ K U = ½ D c² (κ_11 = c, no membrane strain)."""
    q, _ = make_polynomial_plate()
    c = 0.7
    U = np.zeros((6, 3))
    U[3, 2] = 0.5 * c  # node 3 carries the basis x²
    K = linear_stiffness(q, material)
    W = 0.5 * U.ravel() @ (K @ U.ravel())
    assert W == pytest.approx(0.5 * material.bending_rigidity * c ** 2, rel=1e-12)


def test_strain_displacement_matrices_membrane_rows(cylinder_patch):
    q, P = cylinder_patch
    M, B = strain_displacement_matrices(q)
    t = 5
    p1, p2 = q.basis[t, 1], q.basis[t, 2]
    X1, X2 = q.tangents[0, 0], q.tangents[0, 1]
    assert np.allclose(M[t], [p1 * X1, p2 * X2, p2 * X1 + p1 * X2])
    # translation gives no bending strain: Σ_a B_a = 0 at every point
    sums = np.add.reduceat(B, q.indptr[:-1], axis=0)
    assert abs(sums).max() < 1e-9 * abs(B).max()
