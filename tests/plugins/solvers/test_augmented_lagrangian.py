"""The augmented-Lagrangian solve equals the exact constrained minimiser (KKT system)."""
import numpy as np
import pytest
from scipy.sparse import csr_matrix

from pointatlas.errors import InputError
from pointatlas_solvers.augmented_lagrangian import solve_augmented


def _problem(n=30, r=4, seed=0):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    K = A @ A.T + n * np.eye(n)
    C = rng.normal(size=(r, n))
    return K, rng.normal(size=n), C, rng.normal(size=r)


def _kkt(K, F, C, g):
    n, r = K.shape[0], C.shape[0]
    M = np.block([[K, C.T], [C, np.zeros((r, r))]])
    return np.linalg.solve(M, np.concatenate([F, g]))[:n]


@pytest.mark.parametrize("backend", ["superlu", "direct", "cg_ilu", "pardiso", "cg_amg", "auto"])
def test_matches_kkt_solution(backend):
    from pointatlas_solvers.linear_backends import installed

    if not installed(backend):
        pytest.skip(f"{backend} is not installed (pip install 'pointatlas[fast]')")
    K, F, C, g = _problem()
    U, lam, info = solve_augmented(csr_matrix(K), F, csr_matrix(C), g, penalty=1e3,
                                   tol=1e-12, backend=backend)
    exact = _kkt(K, F, C, g)
    if backend.startswith("cg_"):
        # CG stops at a relative residual of 1e-12: errors up to cond(K_ρ) ≈ 1e3 times that
        np.testing.assert_allclose(U, exact, rtol=0, atol=1e-7 * np.abs(exact).max())
    else:
        np.testing.assert_allclose(U, exact, rtol=1e-8, atol=1e-10)
    assert info.violation < 1e-10 * np.abs(U).max()
    # the direct backends give the inertia of K + ρCᵀC (positive definite here)
    assert info.negative_pivots == (0 if backend in ("superlu", "direct", "pardiso", "auto")
                                    else -1)


def test_redundant_constraints_are_harmless():
    K, F, C, g = _problem()
    C2 = np.vstack([C, C[:2] * 3.0])
    g2 = np.concatenate([g, g[:2] * 3.0])
    U, _, _ = solve_augmented(csr_matrix(K), F, csr_matrix(C2), g2, tol=1e-12)
    np.testing.assert_allclose(U, _kkt(K, F, C, g), rtol=1e-8, atol=1e-10)


def test_singular_problem_is_reported():
    K = np.diag([1.0, 1.0, 0.0])
    with pytest.raises(InputError, match="singular"):
        solve_augmented(csr_matrix(K), np.ones(3), csr_matrix((0, 3)), np.zeros(0))
