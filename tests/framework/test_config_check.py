"""Start-up checks of a composed config (issue 15: seed, outputs_root, plugin settings)."""
import dataclasses

import pytest

from pointatlas import registry
from pointatlas.config_check import build_checked, check_outputs_root, check_seed
from pointatlas.errors import ConfigError


@pytest.mark.parametrize("seed", [0, 1, 2**64 - 1])
def test_seeds_in_the_unsigned_64_bit_range_pass(seed):
    assert check_seed(seed) == seed


@pytest.mark.parametrize("seed", [-1, 2**64, 1.5, True, "3"])
def test_other_seeds_are_refused(seed):
    with pytest.raises(ConfigError, match="seed=.* is invalid.*2\\*\\*64 - 1"):
        check_seed(seed)


def test_outputs_root_that_is_a_file_is_refused(tmp_path):
    (tmp_path / "f").write_text("x")
    with pytest.raises(ConfigError, match="is a file"):
        check_outputs_root(tmp_path / "f")
    with pytest.raises(ConfigError, match="cannot be created"):
        check_outputs_root(tmp_path / "f" / "sub")
    assert check_outputs_root(tmp_path / "new") == tmp_path / "new"


class Fussy:
    """A third-party plugin that validates in ``__init__`` with a plain ValueError."""

    @dataclasses.dataclass
    class Config:
        width: float = 1.0

    description = "fussy"

    def __init__(self, *, width: float = 1.0):
        if width <= 0:
            raise ValueError(f"width must be positive, got {width}")
        self.width = width


def test_a_plugin_value_error_becomes_one_config_error(monkeypatch):
    monkeypatch.setattr(registry, "load_plugin", lambda family, name: Fussy)
    monkeypatch.setattr("pointatlas.config_check.load_plugin", lambda family, name: Fussy)
    with pytest.raises(ConfigError) as info:
        build_checked("source", "fussy", {"width": -2.0})
    message = str(info.value)
    assert "\n" not in message and "source plugin 'fussy'" in message
    assert "width must be positive, got -2.0" in message and "source.<key>=<value>" in message
    assert build_checked("source", "fussy", {"width": 3.0}).width == 3.0


def test_check_config_errors_name_the_family_key():
    with pytest.raises(ConfigError, match=r"^source\.n_points=-5 is invalid"):
        build_checked("source", "sphere", {"n_points": -5})
