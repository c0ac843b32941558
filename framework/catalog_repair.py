"""Rebuild the run catalog from the run directories, and collect what killed writes left.

The catalog is an index, not the only copy: every run directory holds ``run.json`` (written
when the run starts: id, experiment, overrides, process) and, once it finished,
``results.nc`` (with the same facts and the metrics as attributes) or ``error.txt``.
:func:`rebuild_catalog` moves a damaged catalog aside (``catalog.sqlite.damaged-<time>``) and
writes a new one from those files; :func:`collect_garbage` removes the temporary files of
interrupted writes in the directories of runs that are no longer alive.
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

from .catalog import Catalog, catalog_path
from .liveness import pid_alive
from .run_files import ERROR_FILE, PARTIAL_PATTERNS, RESULTS_NAME, RUN_FILE


@dataclass
class RepairReport:
    moved_aside: list[Path] = field(default_factory=list)
    kept: int = 0
    completed: int = 0
    failed: int = 0
    unfinished: int = 0
    unreadable: list[Path] = field(default_factory=list)

    def text(self, path: Path) -> str:
        moved = (f"moved the old catalog to {', '.join(map(str, self.moved_aside))}; "
                 if self.moved_aside else "")
        skipped = (f"; {len(self.unreadable)} unreadable results files skipped "
                   f"({', '.join(map(str, self.unreadable[:3]))}{', ...' if len(self.unreadable) > 3 else ''})"
                   if self.unreadable else "")
        kept = (f"{self.kept} rows of the old catalog kept; " if self.kept else
                "the old catalog could not be read: only run directories under the root were "
                "found; " if self.moved_aside else "")
        return (f"{moved}{kept}rebuilt {path} from the run directories: {self.completed} "
                f"completed, {self.failed} failed, {self.unfinished} unfinished runs{skipped}")


def _results_facts(path: Path) -> dict:
    """The catalog facts stored in a results file's attributes and scalar variables."""
    import netCDF4

    with netCDF4.Dataset(path) as nc:
        attrs = {k: nc.getncattr(k) for k in nc.ncattrs()}
        metrics = {}
        for name in json.loads(attrs.get("metrics", "[]")):
            if name in nc.variables and nc.variables[name].ndim == 0:
                metrics[name] = float(nc.variables[name][...])
    plugins = json.loads(attrs.get("plugins", "{}"))
    params = {**plugins, "seed": str(attrs.get("seed", ""))}
    try:  # the resolved settings the run recorded beside its results
        params = {**json.loads((path.parent / "run.json").read_text()).get("params", {}),
                  **params}
    except (OSError, ValueError, AttributeError):
        pass
    return {
        "run_id": str(attrs["run_id"]), "experiment": str(attrs.get("experiment", "default")),
        "overrides": json.loads(attrs.get("overrides", "[]")),
        "params": params,
        "git_commit": str(attrs.get("git_commit", "")),
        "start_time": str(attrs.get("start_time", "")), "end_time": str(attrs.get("end_time", "")),
        "wall_time_s": float(attrs.get("wall_time_s", float("nan"))), "metrics": metrics,
        "status": "completed_with_warnings" if str(attrs.get("status")) ==
        "completed_with_warnings" else "completed",
    }


def _run_dirs(root: Path):
    """Directories under ``root`` that hold a run (a run.json or a results file)."""
    seen = set()
    for pattern in (f"**/{RUN_FILE}", f"**/{RESULTS_NAME}"):
        for path in root.glob(pattern):
            if path.parent not in seen:
                seen.add(path.parent)
                yield path.parent


def _readable_records(path: Path) -> list:
    """The rows of the catalog at ``path``, or [] when it is missing or cannot be read."""
    import sqlite3

    if not path.is_file():
        return []
    try:
        return Catalog(path).runs()
    except (sqlite3.Error, OSError, ValueError):
        return []


def _copy(catalog: Catalog, record) -> None:
    catalog.start(run_id=record.id, experiment=record.experiment, overrides=record.overrides,
                  path=record.path, git_commit=record.git_commit,
                  start_time=record.start_time or "", params=record.params,
                  process={"pid": record.pid, "host": record.host, "pid_start": record.pid_start}
                  if record.pid else None)
    if record.recorded_status in ("completed", "completed_with_warnings", "failed"):
        catalog.finish(record.id, status=record.recorded_status, end_time=record.end_time or "",
                       wall_time_s=record.wall_time_s if record.wall_time_s is not None
                       else float("nan"), metrics=record.metrics, error=record.error)


def rebuild_catalog(root: str | Path) -> RepairReport:
    """Move the catalog under ``root`` aside (when present) and rebuild it: the rows that can
    still be read are kept, and every run directory found under ``root`` or named by those rows
    is read again (its results file is the truth for a finished run)."""
    root = Path(root)
    path = catalog_path(root)
    report = RepairReport()
    kept = _readable_records(path)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for suffix in ("", "-wal", "-shm"):
        old = Path(str(path) + suffix)
        if old.exists():
            target = Path(f"{path}.damaged-{stamp}{suffix}")
            os.replace(old, target)
            report.moved_aside.append(target)
    catalog = Catalog(path)
    for record in kept:
        _copy(catalog, record)
    report.kept = len(kept)
    dirs = set(_run_dirs(root)) | {Path(r.path) for r in kept if r.path and Path(r.path).is_dir()}
    for run_dir in sorted(dirs):
        results, meta = run_dir / RESULTS_NAME, run_dir / RUN_FILE
        if results.is_file():
            try:
                facts = _results_facts(results)
            except Exception:  # noqa: BLE001 - a damaged file is reported, not fatal
                report.unreadable.append(results)
            else:
                catalog.start(run_id=facts["run_id"], experiment=facts["experiment"],
                              overrides=facts["overrides"], path=str(run_dir),
                              git_commit=facts["git_commit"], start_time=facts["start_time"],
                              params=facts["params"])
                catalog.finish(facts["run_id"], status=facts["status"], end_time=facts["end_time"],
                               wall_time_s=facts["wall_time_s"], metrics=facts["metrics"])
                report.completed += 1
                continue
        if not meta.is_file():
            continue
        try:
            info = json.loads(meta.read_text())
        except (OSError, ValueError):
            continue
        process = {k: info.get(k) for k in ("pid", "host", "pid_start")}
        catalog.start(run_id=str(info["run_id"]), experiment=str(info.get("experiment", "default")),
                      overrides=list(info.get("overrides", [])), path=str(run_dir),
                      git_commit=str(info.get("git_commit", "")),
                      start_time=str(info.get("start_time", "")),
                      params=dict(info.get("params", {})), process=process)
        error = run_dir / ERROR_FILE
        if error.is_file():
            catalog.finish(str(info["run_id"]), status="failed", end_time="",
                           wall_time_s=float("nan"), metrics={}, error=error.read_text().strip())
            report.failed += 1
        else:
            report.unfinished += 1  # running, or 'died' when its process is gone
    return report


def collect_garbage(root: str | Path) -> list[Path]:
    """Remove the temporary files of interrupted writes under ``root`` and in the run
    directories its catalog names (not those of a run whose process is still alive on this
    host); return the removed paths."""
    from .liveness import hostname

    removed = []
    dirs = {p.parent for pattern in PARTIAL_PATTERNS for p in Path(root).rglob(pattern)}
    # run directories outside the root (hydra.run.dir elsewhere) are known from the catalog
    dirs |= {Path(r.path) for r in _readable_records(catalog_path(Path(root)))
             if r.path and Path(r.path).is_dir()}
    for run_dir in dirs:
        meta = run_dir / RUN_FILE
        try:
            info = json.loads(meta.read_text()) if meta.is_file() else {}
        except (OSError, ValueError):
            info = {}
        if info.get("host") == hostname() and pid_alive(info.get("pid"), info.get("pid_start")):
            continue  # a live run is writing these
        for pattern in PARTIAL_PATTERNS:
            for leftover in run_dir.glob(pattern):
                if leftover.is_file():
                    leftover.unlink(missing_ok=True)
                    removed.append(leftover)
    return sorted(removed)


__all__ = ["rebuild_catalog", "collect_garbage", "RepairReport"]
