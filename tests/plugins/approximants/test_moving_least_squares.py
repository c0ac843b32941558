"""Moving least squares with exact derivatives: reproduction, derivatives of the values,
refusal where the nodes do not determine a polynomial."""
import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pointatlas.errors import ConfigError, InputError
from pointatlas_approximants.lme import LocalMaxEnt
from pointatlas_approximants.moving_least_squares import MovingLeastSquares


def monomials(X, degree):
    """(n, k) all monomials of total degree ≤ degree of the columns of X, and their
    gradients (n, k, d) and Hessians (n, k, d, d)."""
    n, d = X.shape
    exps = [e for e in itertools.product(range(degree + 1), repeat=d) if sum(e) <= degree]
    V, G, H = np.ones((n, len(exps))), np.zeros((n, len(exps), d)), np.zeros((n, len(exps), d, d))
    for c, e in enumerate(exps):
        e = np.array(e)
        V[:, c] = np.prod(X ** e, axis=1)
        for i in range(d):
            ei = e.copy()
            ei[i] -= 1
            if e[i] > 0:
                G[:, c, i] = e[i] * np.prod(X ** np.maximum(ei, 0), axis=1)
            for j in range(d):
                eij = ei.copy()
                eij[j] -= 1
                if e[i] > 0 and eij[j] >= 0:
                    H[:, c, i, j] = e[i] * (e[j] - (i == j)) * np.prod(X ** np.maximum(eij, 0),
                                                                       axis=1)
    return V, G, H


@settings(max_examples=int(__import__("os").environ.get("HYP_N", "10")), deadline=None)
@given(d=st.sampled_from([2, 3]), degree=st.sampled_from([2, 3]),
       gamma=st.floats(0.8, 1.2), seed=st.integers(0, 10**6))
def test_every_polynomial_of_the_degree_and_its_derivatives_are_reproduced(ax, d, degree,
                                                                          gamma, seed):
    """Σ_a φ_a f(x_a) = f, Σ ∇φ_a f_a = ∇f, Σ ∇∇φ_a f_a = ∇∇f for every monomial of degree
    ≤ k, on random non-uniform nodes (the exact derivatives of a reproducing basis
    reproduce the derivatives). Surfaces and volumes: on these clustered nodes in d = 1,
    where two neighbours set h_a, some supports hold too few nodes for a quadratic (refused,
    see the test of refusals)."""
    X = ax.nonuniform_nodes(d, {2: 300, 3: 1200}[d], seed)
    x = ax.inside_points(d, 30, seed)
    P, G, H = ax.dense(MovingLeastSquares(gamma=gamma, degree=degree).fit(X).evaluate(x, 2),
                       len(X))
    F = monomials(X, degree)[0]
    V, GV, HV = monomials(x, degree)
    assert np.allclose(P @ F, V, atol=1e-8)
    assert np.allclose(np.einsum("mnd,nc->mcd", G, F), GV, atol=1e-6)
    assert np.allclose(np.einsum("mnij,nc->mcij", H, F), HV, atol=1e-4)


def test_derivatives_are_those_of_the_values(ax):
    """Gradients and Hessians against 4th-order finite differences of values and gradients
    (step 1e-4; measured 7e-11 and 2e-10 relative). The diffuse derivatives of the
    polynomial-fit geometry basis (LocalMaxEnt reproduction='quadratic') are off by 0.6."""
    X = ax.nonuniform_nodes(2, 250, 3)
    x = ax.inside_points(2, 12, 3)
    for model, exact in ((MovingLeastSquares(gamma=0.8, degree=2), True),
                         (LocalMaxEnt(gamma=0.8, reproduction="quadratic"), False)):
        model.fit(X)
        _, G, H = ax.dense(model.evaluate(x, 2), len(X))
        dP, dG = ax.finite_differences(model, x, 1e-4)
        errors = ax.rel_err(G, dP), ax.rel_err(H, dG)
        assert (max(errors) < 1e-8) if exact else (max(errors) > 0.1), errors


def test_one_degree_more_than_lme_reproduces():
    """LME reproduces linear functions only: a quadratic is off by O(h²), MLS exact."""
    rng = np.random.default_rng(0)
    X = rng.random((400, 2))
    x = 0.3 + 0.4 * rng.random((50, 2))
    f = X[:, 0] ** 2 - X[:, 0] * X[:, 1]
    exact = x[:, 0] ** 2 - x[:, 0] * x[:, 1]
    errors = []
    for model in (LocalMaxEnt(gamma=1.8), MovingLeastSquares()):
        B = model.fit(X).evaluate(x, 0)
        rows = np.repeat(np.arange(len(x)), np.diff(B.indptr))
        errors.append(np.abs(np.bincount(rows, B.values * f[B.indices], len(x)) - exact).max())
    assert errors[0] > 1e-3 and errors[1] < 1e-11


def test_nodes_that_cannot_carry_the_degree_are_refused_or_flagged():
    """Nodes on two parallel lines: linear functions are determined (LME exists between
    them), a quadratic across the lines is not (M singular): refused in one line, or
    flagged with outside='flag'."""
    t = np.linspace(0.0, 1.0, 30)
    X = np.vstack([np.column_stack([t, np.zeros_like(t)]), np.column_stack([t, np.ones_like(t)])])
    x = np.array([[0.5, 0.5], [0.4, 0.3]])
    LocalMaxEnt(gamma=0.8).fit(X).evaluate(x, 1)  # LME exists there
    with pytest.raises(InputError, match="do not determine a polynomial of degree 2"):
        MovingLeastSquares(gamma=0.8).fit(X).evaluate(x, 1)
    B = MovingLeastSquares(gamma=0.8, outside="flag").fit(X).evaluate(x, 1)
    assert B.outside.all() and B.indptr[-1] == 0


def test_points_outside_the_hull_are_refused_as_lme_refuses_them():
    X = np.random.default_rng(1).random((100, 2))
    with pytest.raises(InputError, match="outside the convex hull"):
        MovingLeastSquares().fit(X).evaluate(np.array([[2.0, 2.0]]), 0)


def test_config_is_checked():
    with pytest.raises(ConfigError, match="degree"):
        MovingLeastSquares(degree=5).fit(np.random.default_rng(2).random((50, 2)))
