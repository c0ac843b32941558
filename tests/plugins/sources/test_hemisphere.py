"""Pinched hemisphere (Paper 1 §4.4): R = 10, closed at the pole or with an 18° hole."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError
from pointatlas_sources.hemisphere import Hemisphere

CASES = [("full", 0.0), ("full", 18.0), ("quarter", 0.0), ("quarter", 18.0)]


@pytest.mark.parametrize("model, hole", CASES)
@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_on_the_hemisphere_with_boundaries(model, hole, sampling):
    pc = Hemisphere(n_points=500, model=model, hole_angle_deg=hole, sampling=sampling).load(
        np.random.default_rng(0))
    X, P = pc.points, pc.parameters
    assert abs(len(X) - 500) / 500 < 0.15
    np.testing.assert_allclose(np.linalg.norm(X, axis=1), 10.0, atol=1e-12)
    assert X[:, 2].min() == 0.0
    assert np.sum(X[:, 2] == 0.0) >= 10  # the equator
    t0 = np.deg2rad(hole)
    assert P[:, 0].min() == pytest.approx(t0, abs=1e-15)
    if hole > 0:
        assert np.sum(np.abs(P[:, 0] - t0) < 1e-12) >= 5  # the hole edge
        assert X[:, 2].max() == pytest.approx(10 * np.cos(t0), abs=1e-12)
    else:
        assert np.sum(np.linalg.norm(X - [0, 0, 10], axis=1) < 1e-12) == 1  # one pole point
    if model == "quarter":
        assert X[:, :2].min() >= -1e-12
        assert np.sum(np.abs(X[:, 0]) < 1e-12) >= 5 and np.sum(np.abs(X[:, 1]) < 1e-12) >= 5
    fraction = 0.25 if model == "quarter" else 1.0
    assert pc.exact["area"] == pytest.approx(fraction * 2 * np.pi * 100 * np.cos(t0))
    assert pc.exact["euler_characteristic"] == (0 if (model, hole) == ("full", 18.0) else 1)
    assert len(np.unique(X, axis=0)) == len(X)
    assert 0.15 < len(pc.markers) / len(X) < 0.35


def test_structured_has_the_load_points_and_is_quasi_uniform():
    X = Hemisphere(n_points=1500).load(np.random.default_rng(0)).points
    for p in ([10, 0, 0], [-10, 0, 0], [0, 10, 0], [0, -10, 0]):
        assert np.min(np.linalg.norm(X - p, axis=1)) < 1e-12
    from scipy.spatial import cKDTree
    d = cKDTree(X).query(X, k=2)[0][:, 1]
    assert d.min() > 0.6 * np.median(d) and d.max() < 1.5 * np.median(d)
    assert pointatlas.load_plugin("sources", "hemisphere") is Hemisphere


def test_seeding_and_random_differs():
    s = Hemisphere(n_points=400, sampling="random", hole_angle_deg=18.0)
    a = s.load(np.random.default_rng(7)).points
    np.testing.assert_array_equal(a, s.load(np.random.default_rng(7)).points)
    assert not np.allclose(a, s.load(np.random.default_rng(8)).points)


@pytest.mark.parametrize("hole", [-1.0, 90.0, "18"])
def test_bad_hole(hole):
    with pytest.raises(ConfigError, match="hole_angle_deg"):
        Hemisphere(hole_angle_deg=hole).load(np.random.default_rng(0))
