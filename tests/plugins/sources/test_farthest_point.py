"""Farthest-point sampling: the pruned, threaded scan chooses exactly what the plain greedy
scan (the definition, written out here) chooses, ties included."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from pointatlas_sources.farthest_point import farthest_point_order


def plain_greedy(X, n, start):
    """Gonzalez' greedy order by its definition: each pick is the first row farthest from the
    rows picked so far."""
    d2 = np.full(len(X), np.inf)
    chosen, current = [], start
    for _ in range(n):
        chosen.append(current)
        d2 = np.minimum(d2, ((X - X[current]) ** 2).sum(axis=1))
        current = int(np.argmax(d2))
    return np.array(chosen)


@settings(max_examples=40, deadline=None)
@given(m=st.integers(2, 400), dim=st.integers(1, 60), seed=st.integers(0, 10_000),
       lattice=st.booleans())
def test_same_order_as_the_plain_greedy_scan(m, dim, seed, lattice):
    rng = np.random.default_rng(seed)
    X = rng.integers(0, 4, size=(m, dim)).astype(float) if lattice else rng.normal(size=(m, dim))
    n, start = int(rng.integers(1, m + 1)), int(rng.integers(m))
    np.testing.assert_array_equal(farthest_point_order(X, n, start), plain_greedy(X, n, start))


@pytest.mark.parametrize("shape", [(6000, 3), (2500, 400)])
def test_threaded_blocks_on_larger_sets(shape):
    """Sets large enough for several thread blocks: a noisy closed curve in R^D."""
    m, dim = shape
    rng = np.random.default_rng(1)
    t = rng.random(m) * 2 * np.pi
    curve = np.column_stack([np.cos(t), np.sin(t), np.cos(3 * t), np.sin(2 * t)])[:, :dim]
    X = curve @ np.linalg.qr(rng.normal(size=(dim, curve.shape[1])))[0].T
    X += 1e-3 * rng.normal(size=X.shape)
    np.testing.assert_array_equal(farthest_point_order(X, 300, 7), plain_greedy(X, 300, 7))
