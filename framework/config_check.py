"""Start-up checks of a composed run config: what can be refused before any work is done.

:func:`check_run_config` runs on every composed config (each job of a sweep too) before a run
directory exists, so that a bad value exits with one line naming the key, the valid values
and the fix, and leaves nothing behind:

- ``seed``: an integer in [0, 2**64) (the width numpy's ``SeedSequence`` and netCDF's ``u8``
  attribute take);
- ``outputs_root``: a directory, or a path that can become one;
- every selected plugin: built from its config (a ``ValueError``/``TypeError`` from its
  ``__init__`` becomes the same one-line error), then checked by
  :func:`check_plugin_settings`: the parameter constraints its ``Config`` declares
  (:mod:`pointatlas.constraints`: ``n_points >= 4``, a positive radius, a choice among
  options, no NaN), then its ``check_config()`` if it has one (rules that tie settings
  together, files that must exist).
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Mapping

from .constraints import validate_parameters
from .errors import ConfigError, PointatlasError
from .registry import FAMILIES, load_plugin

SEED_MAX = 2**64 - 1


def check_seed(seed: Any) -> int:
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= SEED_MAX:
        raise ConfigError(f"seed={seed!r} is invalid: it must be an integer in [0, 2**64 - 1] "
                          f"(0 to {SEED_MAX}). Pass e.g. seed=0.")
    return seed


def check_outputs_root(root: Any) -> Path:
    path = Path(str(root))
    existing = next((p for p in (path, *path.parents) if p.exists()), None)
    if path.exists() and not path.is_dir():
        raise ConfigError(f"outputs_root={str(root)!r} is a file, not a directory: runs and the "
                          "catalog live in a directory. Pass outputs_root=<a directory>.")
    if existing is not None and existing != path and not existing.is_dir():
        raise ConfigError(f"outputs_root={str(root)!r} cannot be created: {existing} is a file. "
                          "Pass outputs_root=<a directory>.")
    return path


def _prefixed(family: str, fields: set[str], message: str) -> str:
    """``n_points=-5 is invalid`` -> ``source.n_points=-5 is invalid`` (or ``source: ...``)."""
    if message.startswith(f"{family}."):
        return message
    match = re.match(r"([A-Za-z_]\w*)(\s*=|\s)", message)
    if match and match.group(1) in fields:
        return f"{family}.{message}"
    return f"{family}: {message}"


def check_plugin_settings(plugin: Any, prefix: str = "") -> None:
    """The start-up check of a built plugin: the constraints its Config declares, each
    invalid value named ``<prefix>.<key>``, then its ``check_config()`` if it has one."""
    validate_parameters(plugin, prefix=prefix)
    check = getattr(plugin, "check_config", None)
    if callable(check):
        check()


def build_checked(family: str, name: str, kwargs: Mapping[str, Any]):
    """The plugin ``name`` of ``family`` built from ``kwargs`` and checked; ConfigError naming
    ``family.key`` otherwise."""
    import dataclasses

    cls = load_plugin(family, name)
    config = getattr(cls, "Config", None)
    fields = {f.name for f in dataclasses.fields(config)} if config else set()
    try:
        plugin = cls(**dict(kwargs))
        check_plugin_settings(plugin, prefix=family)
    except PointatlasError as exc:
        if isinstance(exc, ValueError):  # ConfigError, InputError
            raise ConfigError(_prefixed(family, fields, str(exc))) from None
        raise
    except (ValueError, TypeError) as exc:
        raise ConfigError(f"{family} plugin {name!r} refuses its settings: "
                          f"{_prefixed(family, fields, str(exc))}. Fix that value in the config "
                          f"or on the command line ({family}.<key>=<value>).") from None
    return plugin


def check_run_config(config: Mapping[str, Any], choices: Mapping[str, str]) -> None:
    """Refuse a composed run config that cannot run (see the module docstring)."""
    check_seed(config.get("seed", 0))
    check_outputs_root(config.get("outputs_root", "outputs"))
    from .mlflow_tracking import check_tracking

    check_tracking(config)  # tracking=mlflow without mlflow: refused here, one line
    for family in FAMILIES.values():
        name = choices.get(family)
        if not name:
            continue
        node = config.get(family) or {}
        build_checked(family, name, node)


__all__ = ["check_run_config", "check_seed", "check_outputs_root", "build_checked",
           "check_plugin_settings"]
