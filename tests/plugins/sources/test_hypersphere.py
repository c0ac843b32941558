"""The round n-sphere source (default S^3 in R^4)."""
import dataclasses
import inspect

import numpy as np
import pytest

from pointatlas.errors import ConfigError
from pointatlas_sources.hypersphere import Hypersphere, sphere_volume, super_fibonacci_s3

from .conftest import nn_distances


def test_plugin_convention():
    fields = {f.name: f.default for f in dataclasses.fields(Hypersphere.Config)}
    params = inspect.signature(Hypersphere.__init__).parameters
    assert {k: p.default for k, p in params.items() if k != "self"} == fields
    assert all(p.kind is p.KEYWORD_ONLY for k, p in params.items() if k != "self")


def test_volumes():
    assert sphere_volume(1, 2.0) == pytest.approx(4 * np.pi)
    assert sphere_volume(2, 2.0) == pytest.approx(16 * np.pi)
    assert sphere_volume(3, 2.0) == pytest.approx(2 * np.pi**2 * 8)
    assert sphere_volume(4, 1.0) == pytest.approx(8 * np.pi**2 / 3)


@pytest.mark.parametrize("dim", [1, 2, 3])
@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_on_the_sphere_with_angles(dim, sampling):
    pc = Hypersphere(n_points=300, dim=dim, radius=1.5, sampling=sampling,
                     n_markers=80).load(np.random.default_rng(0))
    assert pc.points.shape == (300, dim + 1) and pc.markers.shape == (80, dim + 1)
    assert pc.intrinsic_dim == dim
    np.testing.assert_allclose(np.linalg.norm(pc.points, axis=1), 1.5, atol=1e-12)
    # the angles rebuild the points
    ang = pc.parameters
    x = np.ones((300, dim + 1))
    for k in range(dim):
        x[:, k] *= np.cos(ang[:, k])
        x[:, k + 1:] *= np.sin(ang[:, k])[:, None]
    np.testing.assert_allclose(1.5 * x, pc.points, atol=1e-12)
    assert pc.exact["volume"] == pytest.approx(sphere_volume(dim, 1.5))
    assert pc.exact["euler_characteristic"] == 1 + (-1) ** dim


def test_super_fibonacci_is_quasi_uniform_and_equal_volume():
    X = super_fibonacci_s3(4000)
    d = nn_distances(X)
    assert d.min() / d.mean() > 0.6
    # volume of {x1² + x2² < 1/2} is half of S^3 (r² is uniform)
    assert abs((X[:, 0] ** 2 + X[:, 1] ** 2 < 0.5).sum() - 2000) <= 2
    # and a coordinate half-space holds half the points
    assert abs((X[:, 3] > 0).sum() - 2000) < 60


def test_s3_exact_quantities():
    e = Hypersphere(radius=2.0).load(np.random.default_rng(0)).exact
    assert e["volume"] == pytest.approx(16 * np.pi**2)
    assert e["mean_curvature_squared_integral"] == pytest.approx(9 / 4 * 16 * np.pi**2)
    assert e["total_scalar_curvature"] == pytest.approx(6 / 4 * 16 * np.pi**2)


def test_bad_dim_raises():
    with pytest.raises(ConfigError, match="dim"):
        Hypersphere(dim=0).load(np.random.default_rng(0))
    with pytest.raises(ConfigError, match="random"):
        Hypersphere(dim=4).load(np.random.default_rng(0))
    assert Hypersphere(dim=4, sampling="random", n_points=50).load(
        np.random.default_rng(0)).points.shape == (50, 5)
