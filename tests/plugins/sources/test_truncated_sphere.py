import numpy as np
import pytest

from pointatlas.errors import ConfigError
from pointatlas_sources.truncated_sphere import QuarterTruncatedSphere, TruncatedSphere

from .conftest import nn_distances


@pytest.mark.parametrize("cls", [TruncatedSphere, QuarterTruncatedSphere])
@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_on_the_truncated_sphere(cls, sampling):
    pc = cls(n_points=1200, radius=2.0, cut=0.3, sampling=sampling).load(np.random.default_rng(0))
    X = pc.points
    assert X.shape == (1200, 3)
    np.testing.assert_allclose(np.linalg.norm(X, axis=1), 2.0, atol=1e-12)
    assert X[:, 2].max() <= 0.3 * 2.0 + 1e-12
    if cls is QuarterTruncatedSphere:
        assert X[:, 0].min() >= -1e-12 and X[:, 1].min() >= -1e-12
        assert pc.exact["area"] == pytest.approx(np.pi * 4.0 * 1.3 / 2)
    else:
        assert pc.exact["area"] == pytest.approx(2 * np.pi * 4.0 * 1.3)
        # the points reach all around: all four quadrants populated
        assert ((X[:, 0] < 0) & (X[:, 1] < 0)).sum() > 200
    assert pc.exact["euler_characteristic"] == 1
    # points fill the zone: some close to the cut and close to the south pole
    assert X[:, 2].max() > 0.6 - 0.15 and X[:, 2].min() < -2.0 + 0.05


@pytest.mark.parametrize("cls", [TruncatedSphere, QuarterTruncatedSphere])
@pytest.mark.parametrize("n", [200, 2000])
def test_structured_is_quasi_uniform_and_equal_area(cls, n):
    X = cls(n_points=n).load(np.random.default_rng(0)).points
    d = nn_distances(X)
    assert d.min() / d.mean() > 0.5
    # Archimedes: the fraction of area below z = 0 is 1/(1 + cut) = 2/3
    assert abs((X[:, 2] < 0).mean() - 2 / 3) < 0.03


def test_random_matches_area_and_seeding():
    s = QuarterTruncatedSphere(n_points=6000, sampling="random")
    X = s.load(np.random.default_rng(5)).points
    assert abs((X[:, 2] < 0).mean() - 2 / 3) < 0.03
    np.testing.assert_array_equal(X, s.load(np.random.default_rng(5)).points)
    assert not np.allclose(X, s.load(np.random.default_rng(6)).points)


@pytest.mark.parametrize("cut", [1.0, -1.0, 2.0])
def test_bad_cut(cut):
    with pytest.raises(ConfigError, match="cut"):
        TruncatedSphere(cut=cut).load(np.random.default_rng(0))
