"""@stores_config gives a keyword-only, store-only __init__ mirroring Config."""
from dataclasses import dataclass, field
from typing import List

import pytest

from pointatlas.stores_config import stores_config
from pointatlas.testing import check_contract


@stores_config
class Thing:
    @dataclass
    class Config:
        a: int = 1
        b: List[float] = field(default_factory=lambda: [1.0, 2.0])

    description = "a thing"


def test_defaults_and_values_are_stored():
    t = Thing(a=3)
    assert t.a == 3 and t.b == [1.0, 2.0]
    u = Thing()
    u.b.append(5.0)
    assert Thing().b == [1.0, 2.0]  # defaults are not shared between instances


def test_unknown_keyword_lists_valid_ones():
    with pytest.raises(TypeError, match=r"\['c'\].*valid: \['a', 'b'\]"):
        Thing(c=1)
    with pytest.raises(TypeError):
        Thing(1)


def test_passes_the_plugin_contract():
    check_contract(Thing)


def test_a_class_as_default_factory_is_called_not_stored():
    """field(default_factory=list) gives [] (it gave the class ``list`` itself, so
    kirchhoff_love_fracture's inherited supports were ``list``, not empty)."""
    @stores_config
    class Lists:
        @dataclass
        class Config:
            items: List[int] = field(default_factory=list)
            seen: dict = field(default_factory=dict)

        description = "lists"

    a, b = Lists(), Lists()
    assert a.items == [] and a.seen == {} and a.items is not b.items
