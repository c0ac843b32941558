"""A run's row in the catalog, kept truthful whatever happens to the run.

:class:`RunRecorder` is what the run pipeline and the command line use instead of the
:class:`~pointatlas.catalog.Catalog` directly:

- it records the run with the identity of its process (PID, host, start time) as soon as the
  command starts, before any heavy import, so a run killed during start-up still has a row,
  which then reads as ``died`` (:mod:`pointatlas.liveness`);
- while the run works a heartbeat thread refreshes the row, so a run on another host that
  stops refreshing reads as ``died`` too;
- a catalog that cannot be used (corrupt file, unwritable directory) never stops the run:
  the problem is reported once, on one line, with the fix (``pointatlas-runs repair``), and
  the run computes and writes its results as usual.
"""
from __future__ import annotations

import sqlite3
import sys
from pathlib import Path

from .catalog import Catalog, catalog_path
from .errors import InputError
from .liveness import Heartbeat, identity
from .provenance import now_iso

_REPORTED: set[str] = set()


def report_catalog_problem(path: Path, exc: BaseException) -> None:
    """One line on stderr per catalog and process: what is wrong and how to fix it."""
    key = str(Path(path).resolve())
    if key in _REPORTED:
        return
    _REPORTED.add(key)
    root = Path(path).parent
    detail = " ".join(str(exc).split()) or type(exc).__name__
    print(f"pointatlas: warning: the run catalog {path} cannot be used ({detail}); this run "
          f"is not recorded in it, but its results are written as usual. Fix: "
          f"`pointatlas-runs repair --root {root}` rebuilds the catalog from the results files.",
          file=sys.stderr, flush=True)


class RunRecorder:
    """The catalog row of one run (see the module docstring)."""

    def __init__(self, outputs_root: str | Path, run_id: str):
        self.path = catalog_path(outputs_root)
        self.run_id = run_id
        self._catalog: Catalog | None = None
        self._broken = False
        self._heartbeat: Heartbeat | None = None

    def _call(self, method: str, *args, **kwargs) -> bool:
        """Call a catalog method; on a catalog error report it once and go on without it."""
        if self._broken:
            return False
        try:
            if self._catalog is None:
                self._catalog = Catalog(self.path)
            getattr(self._catalog, method)(*args, **kwargs)
            return True
        except (sqlite3.Error, OSError, InputError) as exc:
            self._broken = True
            report_catalog_problem(self.path, exc)
            return False

    def start(self, *, experiment: str, overrides: list[str], path: str | None,
              git_commit: str, start_time: str, params: dict[str, str] | None = None) -> None:
        """Record the run as running by this process (replaces an earlier row of this id)."""
        self._call("start", run_id=self.run_id, experiment=experiment, overrides=overrides,
                   path=path, git_commit=git_commit, start_time=start_time, params=params,
                   process=identity())

    def forget(self) -> None:
        """Remove the row (the command turned out to be a sweep: its jobs are the runs)."""
        self._call("forget", self.run_id)

    def start_heartbeat(self) -> None:
        if self._heartbeat is None and not self._broken:
            self._heartbeat = Heartbeat(lambda: self._catalog and self._catalog.heartbeat(
                self.run_id, now_iso()))
            self._heartbeat.__enter__()

    def stop_heartbeat(self) -> None:
        if self._heartbeat is not None:
            self._heartbeat.stop()
            self._heartbeat = None

    def completed(self, *, wall_time_s: float, metrics: dict[str, float],
                  warnings: str = "") -> None:
        """Record the end of a run that wrote its results: ``completed``, or
        ``completed_with_warnings`` when the study flagged results it cannot vouch for."""
        self.stop_heartbeat()
        self._call("finish", self.run_id,
                   status="completed_with_warnings" if warnings else "completed",
                   end_time=now_iso(), wall_time_s=wall_time_s, metrics=metrics,
                   error=warnings or None)

    def rejected(self, *, error: str) -> None:
        """The command line was refused at start-up, before any work: not a run that failed
        (hidden from ``pointatlas-runs list`` unless asked for)."""
        self.stop_heartbeat()
        self._call("finish", self.run_id, status="rejected", end_time=now_iso(),
                   wall_time_s=float("nan"), metrics={}, error=error)

    def failed(self, *, wall_time_s: float | None, error: str) -> None:
        self.stop_heartbeat()
        self._call("finish", self.run_id, status="failed", end_time=now_iso(),
                   wall_time_s=wall_time_s if wall_time_s is not None else float("nan"),
                   metrics={}, error=error)


__all__ = ["RunRecorder", "report_catalog_problem"]
