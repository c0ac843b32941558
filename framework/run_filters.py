"""Filters over recorded runs: ``key=value`` on overrides, ``name<op>value`` on metrics."""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Iterable

from .errors import ConfigError

if TYPE_CHECKING:
    from .catalog import RunRecord

WHERE_SYNTAX = "key=value (e.g. embedder=isomap, source.n_points=2000)"
METRIC_SYNTAX = "name<op>value with op one of < <= > >= = != (e.g. stress<10, relative_error<=1e-3)"
_KEY = r"[A-Za-z_][A-Za-z0-9_.\-/@]*"
_WHERE_RE = re.compile(rf"^\s*(?:\+\+|\+|~)?({_KEY})\s*=(.*)$")
_METRIC_RE = re.compile(rf"^\s*({_KEY})\s*(<=|>=|!=|==|=|<|>)\s*(\S+)\s*$")
_OPS: dict[str, Callable[[float, float], bool]] = {
    "<": lambda a, b: a < b,
    "<=": lambda a, b: a <= b,
    ">": lambda a, b: a > b,
    ">=": lambda a, b: a >= b,
    "=": lambda a, b: a == b,
    "==": lambda a, b: a == b,
    "!=": lambda a, b: a != b,
}


@dataclass(frozen=True)
class WhereFilter:
    """``key=value``: the run's override or param ``key`` equals ``value``."""

    key: str
    value: str

    def matches(self, record: RunRecord) -> bool:
        if self.key == "experiment" and _same_value(record.experiment, self.value):
            return True
        settings = record.settings()
        if self.key in settings:
            return _same_value(settings[self.key], self.value)
        # a key without its group (``n_points`` for ``source.n_points``) matches the
        # resolved settings that end with it
        return any(_same_value(v, self.value) for k, v in settings.items()
                   if k.endswith("." + self.key))


@dataclass(frozen=True)
class MetricFilter:
    """``name<op>value``: the run has metric ``name`` and it satisfies the comparison."""

    name: str
    op: str
    value: float

    def matches(self, record: RunRecord) -> bool:
        if self.name not in record.metrics:
            return False
        actual = record.metrics[self.name]
        if actual is None or math.isnan(actual):
            return self.op == "!=" and not math.isnan(self.value)
        return _OPS[self.op](actual, self.value)


def parse_where(text: str) -> WhereFilter:
    """Parse a ``key=value`` filter; :class:`ConfigError` naming the valid syntax otherwise."""
    match = _WHERE_RE.match(text) if isinstance(text, str) else None
    if match is None or match.group(2).startswith("="):
        raise ConfigError(f"bad where filter {text!r}: expected {WHERE_SYNTAX}")
    return WhereFilter(match.group(1), _unquote(match.group(2).strip()))


def parse_metric(text: str) -> MetricFilter:
    """Parse a ``name<op>value`` threshold; :class:`ConfigError` naming the valid syntax otherwise."""
    match = _METRIC_RE.match(text) if isinstance(text, str) else None
    if match is None:
        raise ConfigError(f"bad metric filter {text!r}: expected {METRIC_SYNTAX}")
    name, op, raw = match.groups()
    try:
        value = float(raw)
    except ValueError:
        raise ConfigError(
            f"bad metric filter {text!r}: {raw!r} is not a number; expected {METRIC_SYNTAX}"
        ) from None
    return MetricFilter(name, op, value)


def flatten_settings(config: dict, prefix: str = "", limit: int = 200) -> dict[str, str]:
    """The resolved run config as ``dotted.key -> value`` strings, the way an override spells
    them (``true``, ``null``, ``[1, 2]``), so that the catalog filters and compares what a run
    used, defaults included. Values longer than ``limit`` characters are left out."""
    out: dict[str, str] = {}
    for key, value in (config or {}).items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten_settings(value, name + ".", limit))
            continue
        text = ("null" if value is None else str(value).lower() if isinstance(value, bool)
                else repr(value) if isinstance(value, float) else str(value))
        if len(text) <= limit:
            out[name] = text
    return out


def overrides_as_dict(overrides: Iterable[str]) -> dict[str, str]:
    """Hydra overrides as ``key -> value`` (``+``/``++`` prefixes dropped, ``~key`` -> ``"~"``)."""
    result: dict[str, str] = {}
    for item in overrides:
        text = str(item).strip()
        if text.startswith("~"):
            result[text[1:].split("=", 1)[0]] = "~"
            continue
        text = text.lstrip("+")
        key, sep, value = text.partition("=")
        result[key.strip()] = _unquote(value.strip()) if sep else ""
    return result


def _unquote(text: str) -> str:
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "'\"":
        return text[1:-1]
    return text


def _same_value(actual: str, wanted: str) -> bool:
    actual = _unquote(str(actual).strip())
    if actual == wanted:
        return True
    try:
        return float(actual) == float(wanted)
    except ValueError:
        return False
