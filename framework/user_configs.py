"""A user's own config folders, the Hydra way: ``--config-dir DIR`` (or ``-cd DIR``) and
``hydra.searchpath=[file://DIR,...]`` add folders laid out like ``conf/``: ``DIR/experiment/
<name>.yaml`` is an experiment (``experiment=<name>``, first line ``# @package _global_`` as in
Hydra's own experiment pattern), ``DIR/sweep/<name>.yaml`` a sweep, ``DIR/hydra/launcher/...`` a
launcher preset. Hydra reads them itself for the run; this module finds them for the start-up
check, which composes the command line once before any work.
"""
from __future__ import annotations

from pathlib import Path

from .errors import ConfigError

_DIR_FLAGS = ("--config-dir", "-cd")
GLOBAL_HEADER = "# @package _global_"


def _searchpath_entries(value: str) -> list[str]:
    return [e.strip().strip("'\"") for e in value.strip().strip("[]").split(",") if e.strip()]


def user_config_dirs(argv: list[str]) -> list[Path]:
    """The folders named by ``--config-dir``/``-cd`` and by ``file://`` (or plain-path) entries
    of a ``hydra.searchpath=[...]`` override, in command-line order; ``pkg://`` entries are left
    to Hydra. A folder that does not exist is refused with the path to fix."""
    found: list[str] = []
    for i, arg in enumerate(argv):
        if arg in _DIR_FLAGS and i + 1 < len(argv):
            found.append(argv[i + 1])
        elif arg.split("=", 1)[0] in _DIR_FLAGS and "=" in arg:
            found.append(arg.split("=", 1)[1])
        elif arg.lstrip("+").startswith("hydra.searchpath="):
            for entry in _searchpath_entries(arg.split("=", 1)[1]):
                if entry.startswith("file://"):
                    found.append(entry[len("file://"):])
                elif "://" not in entry:
                    found.append(entry)
    dirs = []
    for text in found:
        path = Path(text).expanduser().resolve()
        if not path.is_dir():
            raise ConfigError(f"config directory {text!r} does not exist (--config-dir / "
                              "hydra.searchpath). Fix the path.")
        dirs.append(path)
    for path in dirs:
        for file in sorted((path / "experiment").glob("*.yaml")):
            first = file.read_text().lstrip().splitlines()[:1]
            if first != [GLOBAL_HEADER]:
                raise ConfigError(f"experiment {file} must start with the line "
                                  f"'{GLOBAL_HEADER}' (its keys are top-level run keys). "
                                  "Add that line.")
    return dirs


def searchpath_override(dirs: list[Path]) -> list[str]:
    """The ``hydra.searchpath`` override that makes a composition see ``dirs``."""
    if not dirs:
        return []
    return ["hydra.searchpath=[" + ",".join(f"file://{d}" for d in dirs) + "]"]


__all__ = ["user_config_dirs", "searchpath_override", "GLOBAL_HEADER"]
