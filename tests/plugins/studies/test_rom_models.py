"""The comparison's kernels: Eq. 13, Eq. 12 for PCA, Eq. 11, and the reduced run's and
embedding's refusals, on analytic data."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from pointatlas.context import RunContext
from pointatlas.errors import InputError
from pointatlas_reduction.reduced_lagrangian import ReducedLagrangian
from pointatlas_reduction.slow_manifold import SlowManifold
from pointatlas_studies.rom_models import (initial_velocity, nonlinear_manifold,
                                           pca_manifold, pca_reconstruction_error,
                                           reduced_run, trajectory_distance)


def test_trajectory_distance_eq13():
    X = np.array([[3.0, 4.0], [0.0, 5.0]])
    m = np.array([1.0, 4.0])
    Y = X + np.array([[1.0, 0.0], [0.0, 0.5]])
    # |x|_M: √(9 + 64) = √73 and √100 = 10; |x − y|_M: 1 and √(4 · 0.25) = 1
    assert trajectory_distance(X, Y, m) == pytest.approx(2 / (np.sqrt(73) + 10))
    assert trajectory_distance(X, X, m) == 0.0


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_pca_reconstruction_error_matches_the_projection(seed):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(60, 8)) * np.linspace(3, 0.1, 8) + 5.0
    Z = rng.normal(size=(10, 8)) + 5.0
    mean, comps = pca_manifold(X, 5)
    e = pca_reconstruction_error(mean, comps, Z)
    for d in range(1, 6):
        P = comps[:d]
        R = mean + (Z - mean) @ P.T @ P
        direct = np.mean(np.linalg.norm(Z - R, axis=1) / np.linalg.norm(Z, axis=1))
        assert e[d - 1] == pytest.approx(direct, rel=1e-9, abs=1e-12)
    assert np.all(np.diff(e) <= 1e-15)


def test_initial_velocity_recovers_a_tangent_velocity():
    rng = np.random.default_rng(1)
    J = rng.normal(size=(12, 2))
    qd = np.array([0.3, -1.2])
    m = rng.uniform(0.5, 2.0, 12)
    assert np.allclose(initial_velocity(J, m, J @ qd), qd)
    # a velocity M-orthogonal to the tangent space adds nothing
    n = rng.normal(size=12)
    n -= J @ np.linalg.solve(J.T @ (m[:, None] * J), J.T @ (m * n))
    assert np.allclose(initial_velocity(J, m, J @ qd + n), qd)


def _arc_manifold():
    """A unit circle arc in R² sampled by 400 points, q = the angle (an exact embedding)."""
    ctx = RunContext(config={}, choices={})
    th = np.linspace(-1.0, 1.0, 400)
    X = np.column_stack([np.sin(th), -np.cos(th)])
    sm = SlowManifold(ctx.make("approximant", "lme", gamma=0.8), 40).fit(X, th[:, None])
    return sm


def test_a_reduced_run_that_leaves_the_sampled_region_keeps_its_states():
    sm = _arc_manifold()
    mass = np.ones(2)
    RL = ReducedLagrangian(sm, mass, lambda x: (x[1], np.array([0.0, 1.0])))
    x0 = np.array([0.0, -1.0])
    r = reduced_run(sm, RL, x0, np.array([3.0, 0.0]), mass, 1e-3, 2000, 10)
    assert "left the slow manifold's sampled region" in r.failure
    assert 0.2 < r.reached < 2.0 and len(r.X) == len(r.time) > 5
    assert np.all(np.abs(r.q[:, 0]) <= 1.0)
    ok = reduced_run(sm, RL, x0, np.array([0.5, 0.0]), mass, 1e-3, 500, 10)
    assert ok.failure == "" and ok.reached == pytest.approx(0.5)
    assert ok.start_distance < 1e-3


def test_an_embedding_dimension_above_the_snapshots_is_refused():
    ctx = RunContext(config={}, choices={})
    X = np.random.default_rng(0).normal(size=(3, 5))
    with pytest.raises(InputError, match="not below the number of training snapshots"):
        nonlinear_manifold(ctx, "isomap", 3, X, X, None)
