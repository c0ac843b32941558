"""The affine (PCA) fast path of the reduced Lagrangian gives the general path's terms."""
import numpy as np
from hypothesis import given, settings, strategies as st

from pointatlas_reduction.affine_manifold import AffineManifold
from pointatlas_reduction.reduced_lagrangian import ReducedLagrangian


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), d=st.integers(1, 6))
def test_affine_terms_equal_the_general_ones(seed, d):
    rng = np.random.default_rng(seed)
    D = 30
    P = np.linalg.qr(rng.normal(size=(D, d)))[0].T
    mean, m = rng.normal(size=D), rng.uniform(1, 2, D)
    K = rng.normal(size=(D, D))
    K = K @ K.T

    def pot(x):
        return 0.5 * x @ K @ x + np.sin(x).sum(), K @ x + np.cos(x)

    q = rng.normal(size=d)
    fast = ReducedLagrangian(AffineManifold(mean, P), m, pot).terms(q)
    general_manifold = AffineManifold(mean, P)
    general_manifold.is_affine = False
    slow = ReducedLagrangian(general_manifold, m, pot).terms(q)
    assert np.allclose(fast.mass, slow.mass, rtol=1e-12, atol=1e-12)
    assert np.allclose(fast.force, slow.force, rtol=1e-12, atol=1e-12)
    assert np.isclose(fast.potential, slow.potential, rtol=1e-12)
    assert np.all(slow.mass_derivative == 0) and np.all(fast.mass_derivative == 0)
