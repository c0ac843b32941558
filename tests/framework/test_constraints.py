"""Parameter constraints as data (pointatlas.constraints): the rules, the one validator, the
one message, and the declarations of every installed plugin."""
import dataclasses
import math
from typing import ClassVar, Optional

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from pointatlas.config_check import build_checked
from pointatlas.constraints import (Each, Interval, Options, Types, declared_constraints,
                                    describe, meets, validate_parameters)
from pointatlas.errors import ConfigError, PluginError
from pointatlas.registry import FAMILIES, load_all

finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
CLOSED = ["both", "left", "right", "neither"]


@given(low=st.floats(-1e12, 1e12), width=st.floats(1e-3, 1e6),
       value=st.one_of(finite, st.floats(-1e12, 1e12)), closed=st.sampled_from(CLOSED))
def test_a_float_interval_accepts_exactly_the_values_inside(low, width, value, closed):
    high = low + width
    rule = Interval(float, low, high, closed=closed)
    inside = ((low <= value if closed in ("both", "left") else low < value)
              and (value <= high if closed in ("both", "right") else value < high))
    assert rule.is_satisfied_by(value) == inside
    assert rule.is_satisfied_by(low) == (closed in ("both", "left"))
    assert rule.is_satisfied_by(high) == (closed in ("both", "right"))
    assert Interval(float, low, None).is_satisfied_by(value) == (value >= low)


@given(low=st.integers(-1000, 1000), value=st.integers(-10**6, 10**6))
def test_an_integer_interval_refuses_floats_and_bools(low, value):
    rule = Interval(int, low, None)
    assert rule.is_satisfied_by(value) == (value >= low)
    assert rule.is_satisfied_by(np.int64(value)) == (value >= low)
    assert not rule.is_satisfied_by(float(value))
    assert not rule.is_satisfied_by(True) and not rule.is_satisfied_by(False)


@given(rule=st.sampled_from([Interval(float), Interval(float, 0, None, closed="neither"),
                             Interval(int), Types(float), Options((1.0, 2.0)),
                             Each(Interval(float), length=1)]),
       bad=st.sampled_from([math.nan, math.inf, -math.inf, np.float32("nan"), True, False,
                            np.bool_(True), "1.0", None]))
def test_nan_infinity_and_bools_are_not_numbers(rule, bad):
    value = [bad] if isinstance(rule, Each) else bad
    assert not rule.is_satisfied_by(value)
    assert not meets(value, [rule])


def test_unbounded_float_interval_accepts_ints_and_numpy_floats():
    rule = Interval(float)
    assert rule.is_satisfied_by(3) and rule.is_satisfied_by(np.float32(2.5))
    assert str(rule) == "a finite number"


@given(choice=st.sampled_from(["direct", "cg_ilu", "auto"]), other=st.text())
def test_options_accept_only_their_values(choice, other):
    rule = Options(("direct", "cg_ilu", "auto"))
    assert rule.is_satisfied_by(choice)
    assert rule.is_satisfied_by(other) == (other in ("direct", "cg_ilu", "auto"))
    assert not rule.is_satisfied_by(None) and not rule.is_satisfied_by(["direct"])


def test_options_do_not_mix_bools_numbers_and_strings():
    assert not Options((0, 1, 2)).is_satisfied_by(False)
    assert not Options((0, 1, 2)).is_satisfied_by("1")
    assert Options((True,)).is_satisfied_by(True) and not Options((True,)).is_satisfied_by(1)
    assert not Options(("a",)).is_satisfied_by(np.array(["a", "a"]))


def test_types_and_none():
    assert Types(bool).is_satisfied_by(True) and not Types(bool).is_satisfied_by(1)
    assert Types(str).is_satisfied_by("x") and not Types(str).is_satisfied_by(None)
    assert not Types(int).is_satisfied_by(True)
    assert meets(None, [Interval(int, 1, None), None])
    assert not meets(None, [Interval(int, 1, None)])


@given(vector=st.lists(finite, min_size=0, max_size=5))
def test_each_checks_the_length_and_every_item(vector):
    rule = Each(Interval(float), length=3)
    assert rule.is_satisfied_by(vector) == (len(vector) == 3)
    assert rule.is_satisfied_by(tuple(vector)) == (len(vector) == 3)
    assert rule.is_satisfied_by(np.array(vector)) == (len(vector) == 3)
    assert not rule.is_satisfied_by("abc") and not rule.is_satisfied_by(1.0)
    if len(vector) == 3:
        assert not rule.is_satisfied_by([*vector[:2], math.nan])


@pytest.mark.parametrize("rule, words", [
    (Interval(int, 1, None), "an integer >= 1"),
    (Interval(float, 0, None, closed="neither"), "a number > 0"),
    (Interval(float, -1, 0.5, closed="neither"), "a number in (-1, 0.5)"),
    (Interval(float, 0, 1, closed="right"), "a number in (0, 1]"),
    (Interval(float, None, 90, closed="neither"), "a number < 90"),
    (Options(("exact", "consistent")), "one of 'exact', 'consistent'"),
    (Types(bool), "a bool (true or false)"),
    (Each(Options((0, 1, 2))), "a list, each one of 0, 1, 2"),
    (Each(Interval(float), length=3), "a list of 3 items, each a finite number"),
])
def test_the_rules_in_words(rule, words):
    assert str(rule) == words


def test_malformed_rules_are_refused_when_declared():
    with pytest.raises(TypeError):
        Interval(str, 0, 1)
    with pytest.raises(ValueError):
        Interval(float, 1, 0)
    with pytest.raises(ValueError):
        Interval(float, 0, 1, closed="open")


@dataclasses.dataclass
class Demo:
    """A Config as a plugin declares it."""

    poisson_ratio: float = 0.3
    n_neighbors: Optional[int] = 12
    solver: str = "direct"
    normal: Optional[list] = None

    parameter_constraints: ClassVar[dict] = {
        "poisson_ratio": [Interval(float, -1, 0.5, closed="neither")],
        "n_neighbors": [Interval(int, 1, None), None],
        "solver": [Options(("direct", "cg_ilu"))],
        "normal": [Each(Interval(float), length=3), None],
    }


def test_the_message_names_the_path_the_value_the_rule_and_an_example():
    with pytest.raises(ConfigError) as info:
        validate_parameters(Demo(poisson_ratio=0.7), prefix="physics")
    assert str(info.value) == ("physics.poisson_ratio=0.7 is invalid: it must be a number in "
                               "(-1, 0.5). Pass e.g. physics.poisson_ratio=0.3.")
    with pytest.raises(ConfigError, match=r"^n_neighbors=0 is invalid: it must be an integer "
                                          r">= 1 or None\. Pass e\.g\. n_neighbors=12\.$"):
        validate_parameters(Demo(n_neighbors=0))
    with pytest.raises(ConfigError, match=r"^solver='magic' is invalid: it must be one of "
                                          r"'direct', 'cg_ilu'\. Pass e\.g\. solver=direct\.$"):
        validate_parameters(Demo(solver="magic"))
    # no example when the default is None (None is not what a user who set it wants)
    with pytest.raises(ConfigError, match=r"^a\.normal=\[1, 2\] is invalid: it must be a list of "
                                          r"3 items, each a finite number or None\.$"):
        validate_parameters(Demo(normal=[1, 2]), prefix="a")
    validate_parameters(Demo(n_neighbors=None, normal=[0, 0, 1]))


@given(value=st.one_of(finite, st.just(math.nan), st.just(math.inf)))
def test_the_validator_agrees_with_the_rule(value):
    inside = math.isfinite(value) and -1 < value < 0.5
    if inside:
        validate_parameters(Demo(poisson_ratio=value))
    else:
        with pytest.raises(ConfigError, match=r"^poisson_ratio="):
            validate_parameters(Demo(poisson_ratio=value))


def test_a_mapping_is_validated_against_given_constraints():
    rules = {"gamma": [Interval(float, 0, None, closed="neither")]}
    validate_parameters({"gamma": 0.8}, rules)
    with pytest.raises(ConfigError, match=r"^atlas\.gamma=-1 is invalid"):
        validate_parameters({"gamma": -1}, rules, prefix="atlas")


def test_a_malformed_declaration_is_a_plugin_error():
    @dataclasses.dataclass
    class FreeText:
        width: float = 1.0
        parameter_constraints: ClassVar[dict] = {"width": "float > 0"}

    @dataclasses.dataclass
    class Misspelt:
        width: float = 1.0
        parameter_constraints: ClassVar[dict] = {"widht": [Interval(float)]}

    with pytest.raises(PluginError, match="must be a non-empty list"):
        declared_constraints(FreeText)
    with pytest.raises(PluginError, match="'widht', which is not a field"):
        validate_parameters(Misspelt())


def installed_configs():
    out = []
    for group, family in FAMILIES.items():
        for name, cls in sorted(load_all(group).items()):
            out.append(pytest.param(family, cls, id=f"{family}-{name}"))
    return out


@pytest.mark.parametrize("family, cls", installed_configs())
def test_declared_constraints_of_every_plugin_name_config_fields_and_hold_for_defaults(family, cls):
    config = cls.Config
    fields = {f.name: f for f in dataclasses.fields(config)}
    declared = declared_constraints(cls)  # PluginError on a malformed declaration
    assert set(declared) <= set(fields), f"{cls.__name__}: {set(declared) - set(fields)}"
    for key, allowed in declared.items():
        default = fields[key].default
        if default is not dataclasses.MISSING:
            assert meets(default, allowed), (
                f"{cls.__name__}.{key} default {default!r} is not {describe(allowed)}")
    # the free-text constraints of old are gone: nothing but declared rules on the plugin class
    assert not isinstance(getattr(cls, "parameter_constraints", None), dict) or (
        getattr(cls, "parameter_constraints") is getattr(config, "parameter_constraints", None))


def test_every_plugin_family_declares_constraints():
    for group, family in FAMILIES.items():
        declared = [name for name, cls in load_all(group).items() if declared_constraints(cls)]
        assert declared, f"no {family} plugin declares parameter constraints"


def test_start_up_refuses_a_declared_bad_value_of_a_plugin_without_check_config():
    # the approximants and embedders have no start-up check of their own: the declared
    # constraints are checked at start-up all the same, named by their config path
    with pytest.raises(ConfigError, match=r"^approximant\.gamma=nan is invalid: it must be a "
                                          r"number > 0\. Pass e\.g\. approximant\.gamma=0\.8\.$"):
        build_checked("approximant", "lme", {"gamma": float("nan")})
    with pytest.raises(ConfigError, match=r"^embedder\.n_neighbors=0 is invalid"):
        build_checked("embedder", "isomap", {"n_neighbors": 0})
    with pytest.raises(ConfigError, match=r"^physics\.poisson_ratio=0\.7 is invalid: it must be "
                                          r"a number in \(-1, 0\.5\)"):
        build_checked("physics", "kirchhoff_love", {"poisson_ratio": 0.7})
    with pytest.raises(ConfigError, match=r"^atlas\.gamma_pu=-4\.0 is invalid"):
        build_checked("atlas", "default", {"gamma_pu": -4.0})
    assert build_checked("embedder", "isomap", {"n_neighbors": 8}).n_neighbors == 8
