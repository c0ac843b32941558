import numpy as np
import pytest

from pointatlas_sources.farthest_point import farthest_point_order
from pointatlas_sources.lattices import allocate_counts, fibonacci_band


@pytest.mark.parametrize("n", [1, 7, 100, 1001])
def test_allocate_counts_sums_and_is_proportional(n):
    w = np.array([0.1, 1.0, 2.5, 0.0, 3.3])
    counts = allocate_counts(n, w)
    assert counts.sum() == n
    assert np.all(np.abs(counts - n * w / w.sum()) < 1.0)


def test_fibonacci_band_equal_area_heights():
    z, phi = fibonacci_band(10, -1.0, 0.5)
    np.testing.assert_allclose(np.diff(z), -0.15)
    assert z[0] == pytest.approx(0.5 - 0.075) and np.all((phi >= 0) & (phi < 2 * np.pi))


def test_farthest_point_order_spreads_points():
    line = np.linspace(0.0, 1.0, 101)[:, None]
    order = farthest_point_order(line, 3, 0)
    np.testing.assert_array_equal(np.sort(line[order, 0]), [0.0, 0.5, 1.0])
