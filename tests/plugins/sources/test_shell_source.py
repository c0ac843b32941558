"""Shared behaviour of the shell-benchmark sources (plate, roof, hemisphere, cylinder)."""
import dataclasses
import inspect

import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError

SHELLS = ["square_plate", "scordelis_lo_roof", "hemisphere", "cylinder"]


@pytest.mark.parametrize("name", SHELLS)
def test_plugin_convention(name):
    cls = pointatlas.load_plugin("sources", name)
    fields = {f.name: f.default for f in dataclasses.fields(cls.Config)}
    params = {k: p for k, p in inspect.signature(cls.__init__).parameters.items() if k != "self"}
    assert {k: p.default for k, p in params.items()} == fields
    assert all(p.kind is p.KEYWORD_ONLY for p in params.values())
    assert isinstance(cls.description, str) and "\n" not in cls.description
    assert set(fields) <= set(cls.Config.parameter_constraints)  # every setting declared
    pytest.importorskip("omegaconf").OmegaConf.structured(cls.Config)
    obj = cls(**fields)
    assert all(getattr(obj, k) == v for k, v in fields.items())  # __init__ only stores


@pytest.mark.parametrize("name", SHELLS)
@pytest.mark.parametrize("n", [150, 1200])
def test_counts_markers_and_exact(name, n):
    cls = pointatlas.load_plugin("sources", name)
    pc = cls(n_points=n).load(np.random.default_rng(0))
    small = n < 500  # coarse grids (even interval counts) round more
    assert abs(pc.n_points - n) / n < (0.2 if small else 0.06)
    assert 0.15 < len(pc.markers) / pc.n_points < (0.45 if small else 0.35)  # one level coarser
    assert pc.parameters.shape == (pc.n_points, 2) and pc.intrinsic_dim == 2
    assert pc.name == name and pc.exact["area"] > 0 and pc.exact["spacing"] > 0
    m = cls(n_points=n, n_markers=40).load(np.random.default_rng(0)).markers
    assert abs(len(m) - 40) <= 12


@pytest.mark.parametrize("name", SHELLS)
def test_random_is_a_seeded_jitter_of_the_structured_count(name):
    cls = pointatlas.load_plugin("sources", name)
    a = cls(n_points=300, sampling="random").load(np.random.default_rng(11))
    b = cls(n_points=300, sampling="random").load(np.random.default_rng(11))
    s = cls(n_points=300).load(np.random.default_rng(11))
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.markers, b.markers)
    assert a.n_points == s.n_points and not np.allclose(a.points, s.points)


@pytest.mark.parametrize("name", SHELLS)
def test_bad_common_parameters(name):
    cls = pointatlas.load_plugin("sources", name)
    with pytest.raises(ConfigError, match="model="):
        cls(model="half").load(np.random.default_rng(0))
    with pytest.raises(ConfigError, match="sampling.*structured"):
        cls(sampling="uniform").load(np.random.default_rng(0))
    with pytest.raises(ConfigError, match="n_markers"):
        cls(n_points=100, n_markers=100).load(np.random.default_rng(0))
    with pytest.raises(ConfigError, match="default_rng"):
        cls().load(0)
