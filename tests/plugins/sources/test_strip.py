"""Rectangular strip of the in-plane bending fracture study (fracture_bending)."""
import dataclasses
import inspect

import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError
from pointatlas_sources.strip import RectangularStrip


def test_plugin_convention():
    cls = pointatlas.load_plugin("sources", "rectangular_strip")
    assert cls is RectangularStrip
    fields = {f.name: f.default for f in dataclasses.fields(cls.Config)}
    params = inspect.signature(cls.__init__).parameters
    assert {k: p.default for k, p in params.items() if k != "self"} == fields
    assert all(p.kind is p.KEYWORD_ONLY for k, p in params.items() if k != "self")


@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_fill_the_strip_with_its_edges(sampling):
    L, b = 2.0, 0.4
    pc = RectangularStrip(n_points=500, length=L, width=b, sampling=sampling).load(
        np.random.default_rng(1))
    X = pc.points
    assert abs(len(X) - 500) / 500 < 0.2
    assert np.all(X[:, 2] == 0.0)
    assert X[:, 0].min() == pytest.approx(0.0, abs=1e-12)
    assert X[:, 0].max() == pytest.approx(L, abs=1e-12)
    assert np.abs(X[:, 1]).max() == pytest.approx(b / 2, abs=1e-12)
    for edge in (0.0, L):
        assert np.sum(np.abs(X[:, 0] - edge) < 1e-12) >= 5
    assert len(np.unique(X, axis=0)) == len(X)
    np.testing.assert_array_equal(pc.parameters, X[:, :2])
    assert pc.exact["area"] == pytest.approx(L * b)
    assert pc.exact["euler_characteristic"] == 1


def test_structured_grid_is_mirror_symmetric_about_the_mid_line():
    X = RectangularStrip(n_points=600, width=0.3).load(np.random.default_rng(0)).points
    assert np.sum(np.abs(X[:, 1]) < 1e-12) >= 10  # the mid-line is a grid line
    mirrored = X * np.array([1.0, -1.0, 1.0])
    key = lambda Y: Y[np.lexsort(np.round(Y, 12).T[::-1])]
    np.testing.assert_allclose(key(mirrored), key(X), atol=1e-12)
    spacing = np.diff(np.unique(np.round(X[:, 0], 12)))
    assert spacing.std() < 1e-9 * spacing.mean() + 1e-12  # uniform along the strip


@pytest.mark.parametrize("kwargs, word", [({"model": "quarter"}, "model"),
                                          ({"length": 0.0}, "length"),
                                          ({"width": -1.0}, "width"),
                                          ({"n_points": 3}, "n_points")])
def test_bad_parameters(kwargs, word):
    with pytest.raises(ConfigError, match=word):
        RectangularStrip(**kwargs).load(np.random.default_rng(0))
