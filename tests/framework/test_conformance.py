"""The plugin conformance suite (pointatlas.testing) on every installed plugin."""
import numpy as np
import pytest

from pointatlas.registry import FAMILIES, load_all
from pointatlas.testing import check_contract, check_plugin

SMALL = {
    ("source", "file"): None,  # needs a file: built in the test below
    ("source", "connected_pipes"): {"n_points": 400},
    ("source", "open_pipes"): {"n_points": 600},
    ("embedder", "nlie"): {"n_stress_neighbors": 15, "max_iter": 10, "lbfgs_max_iter": 50},
}
LINEAR = {("approximant", "lme")}


def installed():
    return [(family, name, cls) for group, family in FAMILIES.items()
            for name, cls in sorted(load_all(group).items())]


@pytest.mark.parametrize("family,name,cls", installed(), ids=lambda v: v if isinstance(v, str) else "")
def test_plugin_conforms(family, name, cls, tmp_path):
    kwargs = SMALL.get((family, name), {})
    if (family, name) == ("source", "file"):
        np.savez(tmp_path / "p.npz", points=np.random.default_rng(0).random((50, 3)))
        kwargs = {"path": str(tmp_path / "p.npz")}
    if family == "source" and "n_points" not in kwargs and name != "file":
        kwargs = {"n_points": 300}
    if family == "approximant":
        kwargs = {"reproduces_linear": (family, name) in LINEAR}
    check_plugin(family, cls, **kwargs)


def test_the_suite_catches_a_broken_embedder():
    class NoStore:
        description = "broken"

        from dataclasses import dataclass

        @dataclass
        class Config:
            n_components: int = 2

        def __init__(self, *, n_components=2):
            self.n_components = n_components + 1  # does not store unchanged

    with pytest.raises(AssertionError, match="must store 'n_components' unchanged"):
        check_contract(NoStore)
