"""Pinched cylinder (shell obstacle course): R = 300, L = 600, axis z, open ends."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError
from pointatlas_sources.cylinder import Cylinder


@pytest.mark.parametrize("model, fraction", [("full", 1.0), ("quarter", 0.25), ("eighth", 0.125)])
@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_on_the_cylinder_with_edges(model, fraction, sampling):
    pc = Cylinder(n_points=600, model=model, sampling=sampling).load(np.random.default_rng(0))
    X = pc.points
    assert abs(len(X) - 600) / 600 < 0.15
    np.testing.assert_allclose(np.hypot(X[:, 0], X[:, 1]), 300.0, rtol=0, atol=1e-12 * 300)
    z_lo = 0.0 if model == "eighth" else -300.0
    assert X[:, 2].min() == z_lo and X[:, 2].max() == 300.0
    assert np.sum(X[:, 2] == 300.0) >= 8 and np.sum(X[:, 2] == z_lo) >= 8
    if model != "full":
        assert X[:, :2].min() >= -1e-9
        assert np.sum(np.abs(X[:, 0]) < 1e-9) >= 8 and np.sum(np.abs(X[:, 1]) < 1e-9) >= 8
    assert pc.exact["area"] == pytest.approx(fraction * 2 * np.pi * 300 * 600)
    assert pc.exact["euler_characteristic"] == (0 if model == "full" else 1)
    assert len(np.unique(X, axis=0)) == len(X)
    assert len(pc.markers) < 0.35 * len(X)


@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_full_cylinder_is_quasi_uniform_around(sampling):
    X = Cylinder(n_points=2000, sampling=sampling).load(np.random.default_rng(0)).points
    from scipy.spatial import cKDTree
    d = cKDTree(X).query(X, k=2)[0][:, 1]
    assert d.min() > 0.35 * np.median(d) and d.max() < 1.6 * np.median(d)
    if sampling == "structured":  # load points (±R, 0, 0) are grid points
        for p in ([300, 0, 0], [-300, 0, 0]):
            assert np.min(np.linalg.norm(X - p, axis=1)) < 1e-9
    assert pointatlas.load_plugin("sources", "cylinder") is Cylinder


def test_bad_model():
    with pytest.raises(ConfigError, match="model.*full"):
        Cylinder(model="half").load(np.random.default_rng(0))
