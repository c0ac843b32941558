"""Checks of point arrays: duplicates are found in any dimension, with the pairs counted."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from pointatlas.errors import InputError
from pointatlas.pointcloud import check_distinct


def brute_force_pairs(X):
    """Coinciding row pairs by comparing every pair (the definition)."""
    n = len(X)
    return [[a, b] for a in range(n) for b in range(a + 1, n) if np.array_equal(X[a], X[b])]


@settings(max_examples=60, deadline=None)
@given(n=st.integers(2, 30), dim=st.integers(1, 40), seed=st.integers(0, 10_000),
       n_copies=st.integers(0, 6))
def test_duplicates_are_counted_as_pairs_like_the_definition(n, dim, seed, n_copies):
    rng = np.random.default_rng(seed)
    X = rng.integers(-2, 3, size=(n, dim)).astype(float) * rng.random(dim)
    for _ in range(n_copies):                       # copies, some with a signed zero
        a, b = rng.integers(n, size=2)
        X[b] = X[a]
        X[b, X[b] == 0] *= -1.0
    pairs = brute_force_pairs(X)
    if not pairs:
        check_distinct(X)
        return
    with pytest.raises(InputError) as err:
        check_distinct(X)
    first = min(pairs)
    message = str(err.value)
    assert f"{len(pairs)} duplicate pair(s)" in message
    assert f"rows {first}" in message


def test_high_dimensional_snapshots_with_one_repeat():
    X = np.random.default_rng(0).normal(size=(3000, 900))
    check_distinct(X)
    X[2999] = X[17]
    with pytest.raises(InputError, match=r"1 duplicate pair\(s\) \(first: rows \[17, 2999\]\)"):
        check_distinct(X)


def test_a_tolerance_joins_near_points():
    X = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1e-9]])
    check_distinct(X)
    with pytest.raises(InputError, match=r"rows \[1, 2\]"):
        check_distinct(X, tol=1e-6)
