import numpy as np
import pytest
from scipy.integrate import quad

from pointatlas.errors import ConfigError
from pointatlas_sources.swiss_roll import SwissRoll, spiral_arc, spiral_parameter

from .conftest import nn_distances


def test_arc_length_against_quadrature_and_inverse():
    L = quad(lambda t: np.sqrt(1 + t * t), 1.5 * np.pi, 4.5 * np.pi)[0]
    assert spiral_arc(4.5 * np.pi) - spiral_arc(1.5 * np.pi) == pytest.approx(L, rel=1e-12)
    s = np.linspace(0, L, 11)
    t = spiral_parameter(s)
    np.testing.assert_allclose(spiral_arc(t) - spiral_arc(1.5 * np.pi), s, atol=1e-10)
    assert t[0] == pytest.approx(1.5 * np.pi) and t[-1] == pytest.approx(4.5 * np.pi)


@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_on_the_roll(sampling):
    pc = SwissRoll(n_points=1500, sampling=sampling).load(np.random.default_rng(0))
    X = pc.points
    assert X.shape == (1500, 3)
    t = np.hypot(X[:, 0], X[:, 2])
    np.testing.assert_allclose(np.cos(t) * t, X[:, 0], atol=1e-9)
    np.testing.assert_allclose(np.sin(t) * t, X[:, 2], atol=1e-9)
    assert t.min() >= 1.5 * np.pi - 1e-9 and t.max() <= 4.5 * np.pi + 1e-9
    assert 0 <= X[:, 1].min() and X[:, 1].max() <= 21.0
    s, y = pc.parameters.T
    np.testing.assert_allclose(spiral_arc(t) - spiral_arc(1.5 * np.pi), s, atol=1e-8)
    assert pc.exact["area"] == pytest.approx(pc.exact["length"] * 21.0)


def test_structured_is_quasi_uniform():
    X = SwissRoll(n_points=2000, sampling="structured").load(np.random.default_rng(0)).points
    d = nn_distances(X)
    assert d.min() / d.mean() > 0.5


def test_random_uniform_in_arc_length():
    pc = SwissRoll(n_points=20000).load(np.random.default_rng(0))
    s = pc.parameters[:, 0]
    # uniform in arc length (area), not in t: half of the points in the first half of L
    assert (s < pc.exact["length"] / 2).mean() == pytest.approx(0.5, abs=0.015)


def test_noise_and_seeding():
    roll = SwissRoll(n_points=500, noise=0.1)
    a = roll.load(np.random.default_rng(4))
    np.testing.assert_array_equal(a.points, roll.load(np.random.default_rng(4)).points)
    assert not np.allclose(a.points, roll.load(np.random.default_rng(5)).points)
    t = spiral_parameter(a.parameters[:, 0])
    clean = np.column_stack([t * np.cos(t), a.parameters[:, 1], t * np.sin(t)])
    assert np.std(a.points - clean) == pytest.approx(0.1, rel=0.1)


def test_bad_noise():
    with pytest.raises(ConfigError, match="noise"):
        SwissRoll(noise=-1.0).load(np.random.default_rng(0))
