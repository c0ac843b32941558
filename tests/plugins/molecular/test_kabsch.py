"""Kabsch superposition and its chain rule against finite differences and rigid motions."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from pointatlas_molecular.kabsch import align, pull_back


def _xi(z, a, b):
    """A smooth non-linear scalar of the aligned coordinates, and its gradient."""
    t = float(np.sum(b * z))
    return float(np.sum(a * z)) + 0.5 * t * t + np.sin(t), a + (t + np.cos(t)) * b


def _case(seed, n=10):
    rng = np.random.default_rng(seed)
    ref = rng.normal(0, 0.15, (n, 3))
    x = Rotation.random(random_state=seed).apply(ref + rng.normal(0, 0.02, (n, 3))) + 1.3
    w = rng.uniform(0.5, 2.0, n)
    return ref, x, w / w.sum(), rng.normal(size=(n, 3)), rng.normal(size=(n, 3))


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000))
def test_chain_rule_matches_central_differences(seed):
    ref, x, w, a, b = _case(seed)
    refc = ref - w @ ref
    z, R = align(x, ref, w)
    g = _xi(z, a, b)[1]
    out = np.empty_like(x)
    pull_back(g, z, R, refc, w, out)
    h = 1e-6
    fd = np.empty_like(x)
    for i in range(len(x)):
        for k in range(3):
            e = np.zeros_like(x)
            e[i, k] = h
            fd[i, k] = (_xi(align(x + e, ref, w)[0], a, b)[0]
                        - _xi(align(x - e, ref, w)[0], a, b)[0]) / (2 * h)
    assert np.max(np.abs(out - fd)) < 1e-6 * max(1.0, np.max(np.abs(fd)))


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000))
def test_aligned_coordinates_ignore_rigid_motions(seed):
    ref, x, w, _, _ = _case(seed)
    z0, _ = align(x, ref, w)
    moved = Rotation.random(random_state=seed + 1).apply(x) + np.array([3.0, -1.0, 0.5])
    z1, R = align(moved, ref, w)
    assert np.max(np.abs(z1 - z0)) < 1e-12
    assert abs(np.linalg.det(R) - 1) < 1e-12


def test_a_reflected_copy_is_not_superposed_by_a_reflection():
    ref, x, w, _, _ = _case(3)
    z, R = align(-x, ref, w)          # the mirror image: the best proper rotation only
    assert abs(np.linalg.det(R) - 1) < 1e-12
    assert np.sum(w[:, None] * (z - (ref - w @ ref)) ** 2) > 1e-3
