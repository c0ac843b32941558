"""Analytic curve sources (d = 1): circle, helix, trefoil knot."""
import dataclasses
import inspect

import numpy as np
import pytest

from pointatlas.errors import ConfigError
from pointatlas_sources.circle import Circle
from pointatlas_sources.helix import Helix
from pointatlas_sources.trefoil import TrefoilKnot

from .conftest import nn_distances

CURVES = [Circle, Helix, TrefoilKnot]


@pytest.mark.parametrize("cls", CURVES)
def test_plugin_convention(cls):
    fields = {f.name: f.default for f in dataclasses.fields(cls.Config)}
    params = {k: p for k, p in inspect.signature(cls.__init__).parameters.items() if k != "self"}
    assert {k: p.default for k, p in params.items()} == fields
    assert all(p.kind is p.KEYWORD_ONLY for p in params.values())
    assert isinstance(cls.description, str) and "\n" not in cls.description


@pytest.mark.parametrize("cls", CURVES)
@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_counts_markers_and_arc_length_parameters(cls, sampling):
    pc = cls(n_points=240, sampling=sampling, n_markers=60).load(np.random.default_rng(0))
    D = 2 if cls is Circle else 3
    assert pc.points.shape == (240, D) and pc.markers.shape == (60, D)
    assert pc.intrinsic_dim == 1 and pc.parameters.shape == (240, 1)
    s = pc.parameters[:, 0]
    assert np.all(np.diff(s) >= 0) and s[-1] <= pc.exact["length"] + 1e-12
    if not cls.closed:  # an open curve keeps both end points
        assert s[0] == 0 and s[-1] == pytest.approx(pc.exact["length"])
    assert len(np.unique(pc.points, axis=0)) == 240


@pytest.mark.parametrize("cls", CURVES)
def test_structured_is_equally_spaced_in_arc_length(cls):
    pc = cls(n_points=300).load(np.random.default_rng(0))
    gaps = np.diff(pc.parameters[:, 0])
    np.testing.assert_allclose(gaps, pc.exact["length"] / (300 if cls.closed else 299),
                               rtol=1e-5)
    # consecutive points are nearly one arc-length gap apart (chords of a smooth curve)
    chords = np.linalg.norm(np.diff(pc.points, axis=0), axis=1)
    np.testing.assert_allclose(chords, gaps, rtol=1e-2)
    assert nn_distances(pc.points).min() > 0.98 * gaps.min()


def test_circle_exact_values():
    c = Circle(radius=2.5)
    pc = c.load(np.random.default_rng(0))
    np.testing.assert_allclose(np.linalg.norm(pc.points, axis=1), 2.5, atol=1e-12)
    assert pc.exact["length"] == pytest.approx(5 * np.pi)
    assert pc.exact["total_squared_curvature"] == pytest.approx(2 * np.pi / 2.5)
    # the numerical integrals of the base class agree with the closed forms
    num = c.curve_integrals()
    assert num["length"] == pytest.approx(5 * np.pi, rel=1e-13)
    assert num["total_squared_curvature"] == pytest.approx(2 * np.pi / 2.5, rel=1e-12)


def test_helix_closed_forms_match_quadrature():
    h = Helix(radius=0.7, pitch=2.0, turns=1.5)
    exact = h._exact()
    num = h.curve_integrals()
    c = 2.0 / (2 * np.pi)
    assert exact["length"] == pytest.approx(1.5 * 2 * np.pi * np.hypot(0.7, c))
    assert num["length"] == pytest.approx(exact["length"], rel=1e-12)
    assert num["total_squared_curvature"] == pytest.approx(exact["total_squared_curvature"],
                                                           rel=1e-12)


def test_trefoil_scales():
    a = TrefoilKnot(scale=1.0).curve_integrals()
    b = TrefoilKnot(scale=2.0).curve_integrals()
    assert b["length"] == pytest.approx(2 * a["length"], rel=1e-13)
    assert b["total_squared_curvature"] == pytest.approx(a["total_squared_curvature"] / 2,
                                                         rel=1e-12)
    assert a["length"] == pytest.approx(28.826, abs=1e-3)


@pytest.mark.parametrize("bad", [{"radius": -1.0}, {"n_points": 2}, {"sampling": "grid"}])
def test_bad_values_raise(bad):
    with pytest.raises(ConfigError):
        Circle(**bad).load(np.random.default_rng(0))
    with pytest.raises(ConfigError, match="pitch"):
        Helix(pitch=0.0).load(np.random.default_rng(0))
