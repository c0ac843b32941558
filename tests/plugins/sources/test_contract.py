"""Every source plugin follows the plugin convention and loads through the registry."""
import dataclasses
import inspect

import numpy as np
import pytest

import pointatlas

GENERATORS = ["swiss_roll", "sphere", "truncated_sphere", "quarter_truncated_sphere", "torus",
              "connected_pipes"]


@pytest.mark.parametrize("name", [*GENERATORS, "file"])
def test_config_matches_keyword_only_init(name):
    cls = pointatlas.load_plugin("sources", name)
    fields = {f.name: f.default for f in dataclasses.fields(cls.Config)}
    params = {k: p for k, p in inspect.signature(cls.__init__).parameters.items() if k != "self"}
    assert {k: p.default for k, p in params.items()} == fields
    assert all(p.kind is p.KEYWORD_ONLY for p in params.values())
    assert isinstance(cls.description, str) and "\n" not in cls.description
    omegaconf = pytest.importorskip("omegaconf")
    omegaconf.OmegaConf.structured(cls.Config)  # Hydra-compatible field types


@pytest.mark.parametrize("name", GENERATORS)
@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_generators_give_exact_counts_and_markers(name, sampling):
    cls = pointatlas.load_plugin("sources", name)
    pc = cls(n_points=240, sampling=sampling, n_markers=60).load(np.random.default_rng(0))
    assert pc.points.shape == (240, 3) and pc.markers.shape == (60, 3)
    assert pc.intrinsic_dim == 2 and pc.name == name
    assert pc.exact["euler_characteristic"] == 2 - 2 * pc.exact["genus"] - (
        1 if name in ("swiss_roll", "truncated_sphere", "quarter_truncated_sphere") else 0)
    assert len(np.unique(pc.points, axis=0)) == 240
