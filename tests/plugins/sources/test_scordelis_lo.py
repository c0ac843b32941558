"""Scordelis–Lo roof (Paper 1 §4.3): R = 25, L = 50, half angle 40°, axis y."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError
from pointatlas_sources.scordelis_lo import ScordelisLoRoof

T = np.deg2rad(40.0)


@pytest.mark.parametrize("model", ["full", "quarter"])
@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_on_the_roof_with_all_edges(model, sampling):
    pc = ScordelisLoRoof(n_points=500, model=model, sampling=sampling).load(
        np.random.default_rng(1))
    X, P = pc.points, pc.parameters
    assert abs(len(X) - 500) / 500 < 0.15
    np.testing.assert_allclose(np.hypot(X[:, 0], X[:, 2]), 25.0, atol=1e-12)
    np.testing.assert_allclose(np.arctan2(X[:, 0], X[:, 2]), P[:, 0], atol=1e-12)
    np.testing.assert_array_equal(X[:, 1], P[:, 1])
    t_lo, y_lo = (0.0, 0.0) if model == "quarter" else (-T, -25.0)
    assert P[:, 0].min() >= t_lo - 1e-15 and P[:, 0].max() <= T + 1e-15
    for c, edge in [(0, t_lo), (0, T), (1, y_lo), (1, 25.0)]:
        assert np.sum(np.abs(P[:, c] - edge) < 1e-12) >= 8
    quarter = 0.25 if model == "quarter" else 1.0
    assert pc.exact["area"] == pytest.approx(quarter * 25.0 * 2 * T * 50.0)
    assert len(np.unique(X, axis=0)) == len(X)
    assert len(pc.markers) < 0.35 * len(X)


def test_full_roof_has_the_mid_side_of_the_free_edge():
    X = ScordelisLoRoof(n_points=500).load(np.random.default_rng(0)).points
    target = np.array([25 * np.sin(T), 0.0, 25 * np.cos(T)])
    assert np.min(np.linalg.norm(X - target, axis=1)) < 1e-12
    assert pointatlas.load_plugin("sources", "scordelis_lo_roof") is ScordelisLoRoof


def test_seeding():
    s = ScordelisLoRoof(n_points=300, sampling="random")
    np.testing.assert_array_equal(s.load(np.random.default_rng(2)).points,
                                  s.load(np.random.default_rng(2)).points)


@pytest.mark.parametrize("kwargs, word", [({"half_angle_deg": 120.0}, "half_angle_deg"),
                                          ({"radius": 0.0}, "radius"),
                                          ({"model": "eighth"}, "model")])
def test_bad_parameters(kwargs, word):
    with pytest.raises(ConfigError, match=word):
        ScordelisLoRoof(**kwargs).load(np.random.default_rng(0))
