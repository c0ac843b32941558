"""The bound-constrained solve meets the KKT conditions and agrees with scipy's L-BFGS-B."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.optimize import minimize
from scipy.sparse import csr_matrix, diags

from pointatlas.errors import InputError
from pointatlas_solvers.bound_constrained import solve_bounded


def _laplacian_problem(n, seed):
    """A 1-d screened Laplacian (an M-matrix, as a phase field's) with a random load."""
    rng = np.random.default_rng(seed)
    K = diags([-np.ones(n - 1), 2.2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]).tocsr()
    return K, rng.normal(size=n), rng.normal(scale=0.3, size=n)


@settings(max_examples=25, deadline=None)
@given(n=st.integers(5, 40), seed=st.integers(0, 10_000))
def test_kkt_conditions_hold(n, seed):
    K, F, c = _laplacian_problem(n, seed)
    U, info = solve_bounded(K, F, None, np.zeros(0), c)
    assert np.all(U <= c)                     # exactly, not to a tolerance
    mu = F - K @ U                            # the bound multipliers
    active = U == c
    assert np.all(mu[active] >= -1e-10 * np.abs(F).max())
    np.testing.assert_allclose(mu[~active], 0.0, atol=1e-9 * np.abs(F).max())
    assert info.n_active == active.sum()


def _dense_problem(seed, n=25):
    """A dense SPD K (not an M-matrix) with a large random load."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    return A @ A.T + n * np.eye(n), rng.normal(size=n) * 10, rng


def _lbfgsb(K, F, start, bounds):
    """scipy's L-BFGS-B minimiser of ½xᵀKx − Fᵀx in ``bounds`` (the independent answer)."""
    return minimize(lambda x: 0.5 * x @ K @ x - F @ x, start, jac=lambda x: K @ x - F,
                    bounds=bounds, method="L-BFGS-B",
                    options={"ftol": 1e-15, "gtol": 1e-12, "maxiter": 10_000}).x


def test_agrees_with_scipy_lbfgsb_on_a_dense_problem():
    K, F, rng = _dense_problem(3)
    c = rng.normal(size=len(F))
    U, info = solve_bounded(csr_matrix(K), F, None, np.zeros(0), c)
    assert info.n_active > 0 and info.n_active < len(F)     # the bounds bind, not all of them
    np.testing.assert_allclose(U, _lbfgsb(K, F, np.minimum(0, c), [(None, b) for b in c]),
                               atol=1e-6)


def test_with_equality_constraints_matches_the_kkt_system_of_the_final_active_set():
    n = 30
    K, F, c = _laplacian_problem(n, 7)
    c = c + 0.5
    C = np.zeros((2, n))
    C[0, 4], C[1, 20:22] = 1.0, 0.5
    g = np.array([-0.2, 0.1])
    U, info = solve_bounded(K, F, csr_matrix(C), g, c, tol=1e-13)
    np.testing.assert_allclose(C @ U, g, atol=1e-12)
    assert np.all(U <= c)
    inactive = U < c
    # on the inactive set: K U − F + Cᵀλ = 0 for some λ (least squares residual ~ 0)
    r = (K @ U - F)[inactive]
    lam, *_ = np.linalg.lstsq(-C[:, inactive].T, r, rcond=None)
    np.testing.assert_allclose(r + C[:, inactive].T @ lam, 0.0, atol=1e-8)


def test_mismatched_sizes_are_refused():
    K, F, c = _laplacian_problem(10, 0)
    with pytest.raises(InputError, match="agree on 10 unknowns"):
        solve_bounded(K, F[:5], None, np.zeros(0), c)


@settings(max_examples=25, deadline=None)
@given(n=st.integers(5, 40), seed=st.integers(0, 10_000))
def test_two_sided_bounds_meet_the_kkt_conditions(n, seed):
    K, F, c = _laplacian_problem(n, seed)
    lo = c - np.random.default_rng(seed + 1).uniform(0.05, 0.6, size=n)
    U, info = solve_bounded(K, F, None, np.zeros(0), c, lower=lo)
    assert np.all(U <= c) and np.all(U >= lo)     # exactly, not to a tolerance
    mu = F - K @ U
    at_c, at_lo = U == c, U == lo
    atol = 1e-10 * np.abs(F).max()
    assert np.all(mu[at_c] >= -atol) and np.all(mu[at_lo] <= atol)
    np.testing.assert_allclose(mu[~(at_c | at_lo)], 0.0, atol=1e-9 * np.abs(F).max())
    assert info.n_active == (at_c | at_lo).sum()


def test_two_sided_bounds_agree_with_scipy_lbfgsb():
    K, F, _ = _dense_problem(11)
    lo, c = -0.2 * np.ones(len(F)), 0.3 * np.ones(len(F))
    U, info = solve_bounded(csr_matrix(K), F, None, np.zeros(0), c, lower=lo)
    assert (U == lo).any() and (U == c).any()         # both bounds bind somewhere
    np.testing.assert_allclose(U, _lbfgsb(K, F, np.zeros(len(F)), list(zip(lo, c))), atol=1e-6)


def test_crossed_bounds_are_refused():
    K, F, c = _laplacian_problem(10, 0)
    with pytest.raises(InputError, match="lower bound exceeds the upper"):
        solve_bounded(K, F, None, np.zeros(0), c, lower=c + 1.0)
