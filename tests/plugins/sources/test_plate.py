"""Square plate of the pinched-plate benchmark (thesis L1337, Paper 1 §4.2)."""
import dataclasses
import inspect

import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError
from pointatlas_sources.plate import SquarePlate


def test_plugin_convention():
    cls = pointatlas.load_plugin("sources", "square_plate")
    assert cls is SquarePlate
    fields = {f.name: f.default for f in dataclasses.fields(cls.Config)}
    params = inspect.signature(cls.__init__).parameters
    assert {k: p.default for k, p in params.items() if k != "self"} == fields
    assert all(p.kind is p.KEYWORD_ONLY for k, p in params.items() if k != "self")
    pytest.importorskip("omegaconf").OmegaConf.structured(cls.Config)


@pytest.mark.parametrize("model, lo, hi", [("full", -5.0, 5.0), ("quarter", 0.0, 5.0)])
@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_on_plate_with_edges_and_corners(model, lo, hi, sampling):
    pc = SquarePlate(n_points=400, model=model, sampling=sampling).load(np.random.default_rng(0))
    X = pc.points
    assert abs(len(X) - 400) / 400 < 0.15
    assert np.all(X[:, 2] == 0.0)
    assert X[:, :2].min() >= lo - 1e-12 and X[:, :2].max() <= hi + 1e-12
    for c in (0, 1):
        for edge in (lo, hi):
            assert np.sum(np.abs(X[:, c] - edge) < 1e-12) >= 15  # a whole grid line on the edge
    corners = [(a, b) for a in (lo, hi) for b in (lo, hi)]
    for corner in corners:
        assert np.min(np.linalg.norm(X[:, :2] - corner, axis=1)) < 1e-12
    assert len(np.unique(X, axis=0)) == len(X)
    np.testing.assert_array_equal(pc.parameters, X[:, :2])
    assert pc.exact["area"] == pytest.approx((hi - lo) ** 2)
    assert pc.exact["euler_characteristic"] == 1


def test_full_plate_has_its_centre_and_markers_are_one_level_coarser():
    pc = SquarePlate(n_points=400).load(np.random.default_rng(0))
    assert np.min(np.linalg.norm(pc.points, axis=1)) == 0.0
    assert 0.2 < len(pc.markers) / len(pc.points) < 0.36
    from scipy.spatial import cKDTree
    spacing = [np.median(cKDTree(Y).query(Y, k=2)[0][:, 1]) for Y in (pc.points, pc.markers)]
    assert spacing[1] / spacing[0] == pytest.approx(2.0, rel=0.15)
    assert len(SquarePlate(n_points=400, n_markers=50).load(np.random.default_rng(0)).markers) < 70


def test_random_is_seeded_quasi_uniform_and_not_a_grid():
    s = SquarePlate(n_points=900, sampling="random")
    X = s.load(np.random.default_rng(3)).points
    np.testing.assert_array_equal(X, s.load(np.random.default_rng(3)).points)
    assert not np.allclose(X, s.load(np.random.default_rng(4)).points)
    grid = SquarePlate(n_points=900).load(np.random.default_rng(3)).points
    from scipy.spatial import cKDTree
    d = cKDTree(X).query(X, k=2)[0][:, 1]
    assert d.min() > 0.35 * np.median(d)  # no clusters
    assert np.mean(np.linalg.norm(X - grid, axis=1) > 1e-3) > 0.7  # most points moved


@pytest.mark.parametrize("kwargs, word", [({"length": -1.0}, "length"), ({"model": "half"}, "model"),
                                          ({"sampling": "poisson"}, "sampling"),
                                          ({"n_points": 3}, "n_points"),
                                          ({"n_markers": 1000}, "n_markers")])
def test_bad_parameters(kwargs, word):
    with pytest.raises(ConfigError, match=word):
        SquarePlate(**kwargs).load(np.random.default_rng(0))
