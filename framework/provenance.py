"""Provenance of a run: versions, git commit, host, command line, times."""
from __future__ import annotations

import datetime as _dt
import shlex
import socket
import subprocess
import sys
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from .registry import discover, group_name


def now_iso() -> str:
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def git_commit(path: Path | None = None) -> str:
    """The commit of the checkout holding the code (with ``-dirty``), or '' when unknown."""
    cwd = path or Path(__file__).resolve().parent
    try:
        sha = subprocess.run(["git", "rev-parse", "HEAD"], cwd=cwd, capture_output=True,
                             text=True, timeout=5, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=cwd,
                               capture_output=True, text=True, timeout=5).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""
    return f"{sha}-dirty" if dirty else sha


def package_version(dist: str) -> str:
    try:
        return version(dist)
    except PackageNotFoundError:
        return "unknown"


def source_attr(choices: dict[str, str]) -> str:
    """``pointatlas X; embedder=isomap (dist Y); ...`` for the CF ``source`` attr."""
    parts = [f"pointatlas {package_version('pointatlas')}"]
    for family, name in sorted(choices.items()):
        try:
            info = discover(group_name(family)).get(name)
        except Exception:  # noqa: BLE001 - families outside the registry (experiment, sweep)
            continue
        if info is not None:
            parts.append(f"{family}={name} ({info.distribution} {info.version})")
    return "; ".join(parts)


def command_line() -> str:
    return " ".join(shlex.quote(a) for a in [Path(sys.argv[0]).name, *sys.argv[1:]])


def hostname() -> str:
    return socket.gethostname()
