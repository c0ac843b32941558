import dataclasses
import inspect

import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError
from pointatlas_sources.sphere import Sphere

from .conftest import nn_distances


def test_load_plugin_by_name():
    pc = pointatlas.load_plugin("sources", "sphere")(n_points=500).load(np.random.default_rng(0))
    assert pc.points.shape == (500, 3)
    assert pc.intrinsic_dim == 2 and pc.name == "sphere"


def test_config_fields_are_init_keywords():
    fields = {f.name: f.default for f in dataclasses.fields(Sphere.Config)}
    params = inspect.signature(Sphere.__init__).parameters
    assert {k: p.default for k, p in params.items() if k != "self"} == fields
    assert all(p.kind is p.KEYWORD_ONLY for k, p in params.items() if k != "self")


@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_on_sphere_and_parameters(sampling):
    pc = Sphere(n_points=777, radius=2.5, sampling=sampling).load(np.random.default_rng(1))
    X = pc.points
    assert X.shape == (777, 3)
    np.testing.assert_allclose(np.linalg.norm(X, axis=1), 2.5, rtol=0, atol=1e-12)
    theta, phi = pc.parameters.T
    back = 2.5 * np.column_stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                                  np.cos(theta)])
    np.testing.assert_allclose(back, X, atol=1e-12)
    assert pc.exact["area"] == pytest.approx(4 * np.pi * 2.5**2)
    assert pc.exact["willmore_energy"] == pytest.approx(16 * np.pi)
    assert pc.exact["euler_characteristic"] == 2 and pc.exact["genus"] == 0


@pytest.mark.parametrize("n", [100, 500, 3000])
def test_structured_is_quasi_uniform(n):
    X = Sphere(n_points=n).load(np.random.default_rng(0)).points
    d = nn_distances(X)
    assert d.min() / d.mean() > 0.5
    # equal area: each hemisphere and each octant holds its share of the points
    assert abs((X[:, 2] > 0).sum() - n / 2) <= 1
    octant = ((X[:, 0] > 0) & (X[:, 1] > 0) & (X[:, 2] > 0)).sum()
    assert abs(octant - n / 8) < 0.05 * n / 8 + 3


def test_random_is_uniform_in_area():
    X = Sphere(n_points=20000, sampling="random").load(np.random.default_rng(3)).points
    # Archimedes: z is uniform on [-1, 1]; mean 0, variance 1/3
    assert abs(X[:, 2].mean()) < 4 * np.sqrt(1 / 3 / 20000)
    assert X[:, 2].var() == pytest.approx(1 / 3, rel=0.03)
    # a random sample is not quasi-uniform: some nearest neighbours get very close
    assert nn_distances(X[:2000]).min() / nn_distances(X[:2000]).mean() < 0.2


def test_seeding():
    s = Sphere(n_points=300, sampling="random")
    a = s.load(np.random.default_rng(7)).points
    b = s.load(np.random.default_rng(7)).points
    c = s.load(np.random.default_rng(8)).points
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    st = Sphere(n_points=300)
    np.testing.assert_array_equal(st.load(np.random.default_rng(1)).points,
                                  st.load(np.random.default_rng(2)).points)


def test_markers_are_coarser_points_on_the_sphere():
    pc = Sphere(n_points=800, n_markers=200).load(np.random.default_rng(0))
    assert pc.markers.shape == (200, 3)
    np.testing.assert_allclose(np.linalg.norm(pc.markers, axis=1), 1.0, atol=1e-12)
    assert Sphere(n_points=80).load(np.random.default_rng(0)).markers is None


@pytest.mark.parametrize("kwargs, word", [
    ({"radius": -1.0}, "radius"), ({"radius": float("nan")}, "radius"),
    ({"n_points": 2}, "n_points"), ({"n_points": 10.5}, "n_points"),
    ({"sampling": "grid"}, "sampling"), ({"n_points": 100, "n_markers": 100}, "n_markers"),
])
def test_bad_config_raises(kwargs, word):
    with pytest.raises(ConfigError, match=word):
        Sphere(**kwargs).load(np.random.default_rng(0))
