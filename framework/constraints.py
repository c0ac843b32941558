"""Parameter constraints as data, checked by one validator (as scikit-learn >= 1.2 does).

A plugin's ``Config`` declares, for each setting, the constraints a valid value meets; a
value is valid when it meets ANY constraint of its list (``None`` in the list allows None)::

    @dataclass
    class Config:
        gamma: float = 0.8
        outside: str = "error"
        n_neighbors: Optional[int] = None
        parameter_constraints: ClassVar[dict[str, list]] = {
            "gamma": [Interval(float, 0, None, closed="neither")],
            "outside": [Options(("error", "flag"))],
            "n_neighbors": [Interval(int, 1, None), None],
        }

and ``validate_parameters(plugin, prefix="approximant")`` raises, for ``gamma=-1.0``, the one
message format of every invalid setting (the config path as written on the command line,
the value, the rule, a valid example)::

    approximant.gamma=-1.0 is invalid: it must be a number > 0. Pass e.g. approximant.gamma=0.8.

:func:`validate_parameters` runs at start-up on every selected plugin
(:mod:`pointatlas.config_check`) and in the plugins' ``fit``/``load``. Rules that tie several
settings together (exactly one of two, a bound that depends on another setting or on the
data) stay as small explicit checks beside it. No NaN or infinity meets any constraint, and a
bool is not a number. Kept free of numpy: Configs are imported at start-up.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Mapping
from typing import Any, Iterable, Sequence

from .errors import ConfigError, PluginError

CLOSED = ("both", "left", "right", "neither")


class Constraint:
    """A rule one value meets or not; ``str(constraint)`` says the rule in words."""

    def is_satisfied_by(self, value: Any) -> bool:
        """Whether ``value`` meets the rule (never a NaN or an infinity)."""
        return not _nonfinite_number(value) and self._accepts(value)

    def _accepts(self, value: Any) -> bool:  # pragma: no cover - abstract
        raise NotImplementedError


def _is_bool(value: Any) -> bool:
    return isinstance(value, bool) or type(value).__name__ in ("bool", "bool_")  # numpy's too


def _nonfinite_number(value: Any) -> bool:
    return (isinstance(value, numbers.Real) and not _is_bool(value)
            and not math.isfinite(value))


def _num(x: float) -> str:
    return str(x) if isinstance(x, numbers.Integral) else f"{x:g}"


class Interval(Constraint):
    """A finite ``int`` (``type=int``) or real number (``type=float``, ints accepted) between
    ``low`` and ``high`` (None: unbounded on that side); ``closed``: which ends belong to it,
    'both', 'left', 'right' or 'neither'. A bool is not a number here.
    """

    def __init__(self, type: type, low: float | None = None, high: float | None = None, *,
                 closed: str = "both"):
        if type not in (int, float):
            raise TypeError(f"Interval type must be int or float, got {type!r}")
        if closed not in CLOSED:
            raise ValueError(f"Interval closed={closed!r}: use one of {CLOSED}")
        if low is not None and high is not None and low > high:
            raise ValueError(f"Interval low={low!r} is above high={high!r}")
        self.type, self.low, self.high, self.closed = type, low, high, closed

    def _accepts(self, value: Any) -> bool:
        kind = numbers.Integral if self.type is int else numbers.Real
        if _is_bool(value) or not isinstance(value, kind) or not math.isfinite(value):
            return False
        left = self.closed in ("both", "left")
        right = self.closed in ("both", "right")
        if self.low is not None and (value < self.low if left else value <= self.low):
            return False
        return self.high is None or (value <= self.high if right else value < self.high)

    def __str__(self) -> str:
        what = "an integer" if self.type is int else "a number"
        left = self.closed in ("both", "left")
        right = self.closed in ("both", "right")
        if self.low is not None and self.high is not None:
            return (f"{what} in {'[' if left else '('}{_num(self.low)}, {_num(self.high)}"
                    f"{']' if right else ')'}")
        if self.low is not None:
            return f"{what} {'>=' if left else '>'} {_num(self.low)}"
        if self.high is not None:
            return f"{what} {'<=' if right else '<'} {_num(self.high)}"
        return what if self.type is int else "a finite number"

    def __repr__(self) -> str:
        return (f"Interval({self.type.__name__}, {self.low!r}, {self.high!r}, "
                f"closed={self.closed!r})")


class Options(Constraint):
    """One of the given values (a string is not a number and a bool is not an int here)."""

    def __init__(self, values: Iterable[Any]):
        self.values = tuple(values)
        if not self.values:
            raise ValueError("Options needs at least one value")

    def _accepts(self, value: Any) -> bool:
        for option in self.values:
            if (_is_bool(option) == _is_bool(value)
                    and isinstance(option, str) == isinstance(value, str)):
                try:
                    if bool(value == option):
                        return True
                except (TypeError, ValueError):  # an array compared elementwise: not a choice
                    continue
        return False

    def __str__(self) -> str:
        return "one of " + ", ".join(repr(v) for v in self.values)

    def __repr__(self) -> str:
        return f"Options({self.values!r})"


_TYPE_WORDS = {bool: "a bool (true or false)", str: "a string", int: "an integer",
               float: "a finite number", dict: "a mapping", list: "a list"}


class Types(Constraint):
    """An instance of one of ``types`` (a bool is an int only if ``bool`` is listed; NaN and
    infinity are refused as for every constraint)."""

    def __init__(self, *types: type):
        if not types:
            raise ValueError("Types needs at least one type")
        self.types = types

    def _accepts(self, value: Any) -> bool:
        if _is_bool(value):
            return bool in self.types or any(t in (object, numbers.Number) for t in self.types)
        if float in self.types and isinstance(value, numbers.Real):
            return True
        return isinstance(value, self.types)

    def __str__(self) -> str:
        return " or ".join(_TYPE_WORDS.get(t, f"a {t.__name__}") for t in self.types)

    def __repr__(self) -> str:
        return f"Types({', '.join(t.__name__ for t in self.types)})"


class Each(Constraint):
    """A list (any sequence but a string or mapping) of ``length`` items (any length if None)
    of which each meets ANY of ``constraints``: ``Each(Interval(float), length=3)`` is a
    vector of three finite numbers."""

    def __init__(self, *constraints: Constraint | None, length: int | None = None):
        if not constraints:
            raise ValueError("Each needs at least one constraint for its items")
        self.constraints, self.length = constraints, length

    def _accepts(self, value: Any) -> bool:
        if isinstance(value, (str, bytes, Mapping)) or not hasattr(value, "__iter__"):
            return False
        try:
            items = list(value)
        except TypeError:  # a 0-d array
            return False
        if self.length is not None and len(items) != self.length:
            return False
        return all(meets(item, self.constraints) for item in items)

    def __str__(self) -> str:
        size = "a list" if self.length is None else f"a list of {self.length} items"
        return f"{size}, each {describe(self.constraints)}"

    def __repr__(self) -> str:
        return f"Each({', '.join(map(repr, self.constraints))}, length={self.length!r})"


def meets(value: Any, constraints: Sequence[Constraint | None]) -> bool:
    """Whether ``value`` meets ANY of ``constraints`` (``None`` in the list: the value None).
    NaN and infinity meet none."""
    return any(value is None if c is None else c.is_satisfied_by(value) for c in constraints)


def describe(constraints: Sequence[Constraint | None]) -> str:
    """The rule in words: ``"an integer >= 1 or None"``."""
    return " or ".join("None" if c is None else str(c) for c in constraints)


def _config_class(obj: Any) -> type | None:
    config = getattr(obj, "Config", None)
    if config is not None and dataclasses.is_dataclass(config):
        return config
    if dataclasses.is_dataclass(obj):
        return obj if isinstance(obj, type) else type(obj)
    return None


def declared_constraints(obj: Any) -> dict[str, list]:
    """The ``parameter_constraints`` declared on the Config of ``obj`` (a plugin, its class, a
    Config dataclass or an instance of one); ``{}`` if none. :class:`PluginError` on a
    malformed declaration (a constraint written as free text, a key that is not a field)."""
    config = _config_class(obj)
    declared = getattr(config, "parameter_constraints", None) if config is not None else None
    if declared is None:
        return {}
    fields = {f.name for f in dataclasses.fields(config)}
    name = config.__qualname__
    if not isinstance(declared, Mapping):
        raise PluginError(f"{name}.parameter_constraints must be a dict name -> list of "
                        f"constraints, got {type(declared).__name__}")
    for key, allowed in declared.items():
        if key not in fields:
            raise PluginError(f"{name}.parameter_constraints names {key!r}, which is not a field "
                            f"of {name} (fields: {sorted(fields)})")
        if not isinstance(allowed, (list, tuple)) or not allowed or not all(
                c is None or isinstance(c, Constraint) for c in allowed):
            raise PluginError(f"{name}.parameter_constraints[{key!r}] must be a non-empty list of "
                            f"pointatlas.constraints objects (Interval, Options, Types, Each) or "
                            f"None, got {allowed!r}")
    return dict(declared)


def _defaults(obj: Any) -> dict[str, Any]:
    config = _config_class(obj)
    if config is None:
        return {}
    return {f.name: f.default for f in dataclasses.fields(config)
            if f.default is not dataclasses.MISSING}


def _command_line(value: Any) -> str:
    """How a scalar is written as an override: ``null``, ``true``, ``direct``, ``0.8``."""
    if value is None:
        return "null"
    if _is_bool(value):
        return "true" if value else "false"
    return value if isinstance(value, str) else repr(value)


def invalid_message(path: str, value: Any, constraints: Sequence[Constraint | None],
                    example: Any = dataclasses.MISSING) -> str:
    """The one message of an invalid value: the config path, the value, the rule and, when
    ``example`` is given, a valid value to write instead."""
    text = f"{path}={value!r} is invalid: it must be {describe(constraints)}."
    if example is not dataclasses.MISSING:
        text += f" Pass e.g. {path}={_command_line(example)}."
    return text


def validate_parameters(obj: Any, constraints: Mapping[str, Sequence] | None = None,
                        prefix: str = "") -> None:
    """Raise :class:`ConfigError` on the first setting of ``obj`` that meets none of its
    constraints (``constraints``, default: those declared on ``obj``'s Config).

    ``obj``: a plugin, a Config instance or a mapping of settings. ``prefix``: the config path
    of ``obj`` (``"physics"``, ``"physics.supports[0]"``), so that the message names the key
    as it is written in a config or on the command line: ``physics.poisson_ratio=0.7 is
    invalid: it must be a number in (-1, 0.5). Pass e.g. physics.poisson_ratio=0.3.`` The
    example is the Config's default when it is a valid scalar.
    """
    constraints = declared_constraints(obj) if constraints is None else constraints
    defaults = _defaults(obj)
    for key, allowed in constraints.items():
        value = obj[key] if isinstance(obj, Mapping) else getattr(obj, key)
        if meets(value, allowed):
            continue
        path = f"{prefix}.{key}" if prefix else key
        default = defaults.get(key, dataclasses.MISSING)
        usable = (default is not None and isinstance(default, (str, numbers.Number))
                  and meets(default, allowed))
        raise ConfigError(invalid_message(path, value, allowed,
                                          default if usable else dataclasses.MISSING))


__all__ = ["Constraint", "Interval", "Options", "Types", "Each", "meets", "describe",
           "declared_constraints", "validate_parameters", "invalid_message"]
