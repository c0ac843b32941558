"""Collapsed Gauss rules on simplices integrate monomials exactly up to their order."""
import itertools
from math import factorial

import numpy as np
import pytest

from pointatlas.errors import ConfigError
from pointatlas_atlas.quadrature import map_rule_to_simplices, simplex_rule


def monomial_integral(alpha):
    """∫_{T_d} x^α = Π α_i! / (|α| + d)!  on the unit simplex."""
    return np.prod([factorial(a) for a in alpha]) / factorial(sum(alpha) + len(alpha))


@pytest.mark.parametrize("d", [1, 2, 3])
@pytest.mark.parametrize("order", [1, 2, 3, 4, 5, 6, 8])
def test_monomials_exact_up_to_order(d, order):
    rule = simplex_rule(d, order)
    assert np.isclose(rule.weights.sum(), 1 / factorial(d), rtol=1e-14)
    for alpha in itertools.product(range(order + 1), repeat=d):
        if sum(alpha) > order:
            continue
        num = np.sum(rule.weights * np.prod(rule.points ** np.array(alpha), axis=1))
        assert num == pytest.approx(monomial_integral(alpha), rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("d", [2, 3])
def test_not_exact_beyond_order(d):
    rule = simplex_rule(d, 3)
    alpha = (4,) + (0,) * (d - 1)
    num = np.sum(rule.weights * rule.points[:, 0] ** 4)
    assert abs(num - monomial_integral(alpha)) > 1e-8


def test_points_inside_simplex_and_positive_weights():
    r = simplex_rule(3, 6)
    assert (r.points >= 0).all() and (r.points.sum(1) <= 1 + 1e-14).all()
    assert (r.weights > 0).all()


def test_mapped_rule_integrates_over_physical_triangles():
    # two triangles tiling the square [0, 2] x [0, 1]: ∫ x² y dA = (8/3)(1/2)
    V = np.array([[[0, 0], [2, 0], [2, 1]], [[0, 0], [2, 1], [0, 1]]], float)
    x, w = map_rule_to_simplices(V, simplex_rule(2, 3))
    assert np.sum(w * x[:, 0] ** 2 * x[:, 1]) == pytest.approx(4 / 3, rel=1e-13)


@pytest.mark.parametrize("bad", [0, -1, 2.5, True])
def test_bad_order_raises(bad):
    with pytest.raises(ConfigError, match="order"):
        simplex_rule(2, bad)
