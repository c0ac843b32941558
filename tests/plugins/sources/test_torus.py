import numpy as np
import pytest
from scipy.integrate import quad

from pointatlas.errors import ConfigError
from pointatlas_sources.torus import Torus

from .conftest import nn_distances


def torus_implicit(X, R, r):
    rho = np.hypot(X[:, 0], X[:, 1])
    return (rho - R) ** 2 + X[:, 2] ** 2 - r**2


@pytest.mark.parametrize("sampling", ["structured", "random"])
@pytest.mark.parametrize("n", [301, 2000])
def test_points_on_torus(sampling, n):
    pc = Torus(n_points=n, R=2.0, r=0.7, sampling=sampling).load(np.random.default_rng(0))
    assert pc.points.shape == (n, 3)
    assert np.abs(torus_implicit(pc.points, 2.0, 0.7)).max() < 1e-12
    assert pc.parameters.shape == (n, 2)
    assert pc.exact["area"] == pytest.approx(4 * np.pi**2 * 2.0 * 0.7)
    assert pc.exact["euler_characteristic"] == 0 and pc.exact["genus"] == 1


def test_willmore_energy_matches_quadrature():
    R, r = 1.5, 0.4
    integrand = lambda v: ((1 / r + np.cos(v) / (R + r * np.cos(v))) ** 2  # noqa: E731
                           * r * (R + r * np.cos(v)) * 2 * np.pi)
    W = quad(integrand, 0, 2 * np.pi, epsabs=1e-12)[0]
    assert Torus(R=R, r=r, n_points=50).load(np.random.default_rng(0)).exact[
        "willmore_energy"] == pytest.approx(W, rel=1e-10)


@pytest.mark.parametrize("R, r", [(1.0, 0.5), (3.0, 0.5)])
def test_structured_is_quasi_uniform(R, r):
    pc = Torus(n_points=2000, R=R, r=r).load(np.random.default_rng(0))
    d = nn_distances(pc.points)
    assert d.min() / d.mean() > 0.5
    # area-aware: under the area measure r (R + r cos v) du dv, E[cos v] = r / (2R)
    assert np.cos(pc.parameters[:, 1]).mean() == pytest.approx(r / (2 * R), abs=0.01)


def test_random_area_density_and_seeding():
    R, r = 1.0, 0.5
    t = Torus(n_points=20000, R=R, r=r, sampling="random")
    pc = t.load(np.random.default_rng(1))
    X = pc.points
    # E[cos v] = r / (2R) under the area measure (0 if v were uniform); sd of cos v ≈ 0.7
    assert np.cos(pc.parameters[:, 1]).mean() == pytest.approx(r / (2 * R), abs=0.015)
    outer = (np.hypot(X[:, 0], X[:, 1]) > R).mean()
    assert outer == pytest.approx((np.pi * R + 2 * r) / (2 * np.pi * R), abs=0.015)
    np.testing.assert_array_equal(X, t.load(np.random.default_rng(1)).points)
    assert not np.allclose(X, t.load(np.random.default_rng(2)).points)


def test_r_must_be_smaller_than_R():
    with pytest.raises(ConfigError, match="r=1.5"):
        Torus(R=1.0, r=1.5).load(np.random.default_rng(0))
