"""Rows of the run catalog as :class:`RunRecord` objects, with the computed statuses.

A stored status is what the run wrote; what a reader sees adds two computed ones: "died" for a
row left ``running`` by a process that is gone (:func:`pointatlas.liveness.run_alive`) and
"missing" for a run whose directory no longer exists. Standard library only.
"""
from __future__ import annotations

import json
import math
import os
import sqlite3
from dataclasses import dataclass, field

from .liveness import run_alive
from .run_filters import overrides_as_dict

MISSING = "missing"
DIED = "died"


@dataclass
class RunRecord:
    """One run as recorded in the catalog.

    ``status`` is "running", "completed", "completed_with_warnings" or "failed"; "missing" when the recorded run
    directory no longer exists, "died" when a run recorded as running has no live process
    (the stored status is kept in ``recorded_status``).
    Times are ISO 8601 strings (UTC), ``wall_time_s`` in seconds; ``metrics`` maps metric
    name to value (NaN for a non-finite value stored as NULL).
    """

    id: str
    experiment: str
    overrides: list[str] = field(default_factory=list)
    params: dict[str, str] = field(default_factory=dict)
    status: str = "running"
    start_time: str | None = None
    end_time: str | None = None
    wall_time_s: float | None = None
    metrics: dict[str, float] = field(default_factory=dict)
    path: str | None = None
    git_commit: str = ""
    error: str | None = None
    recorded_status: str = ""
    pid: int | None = None
    host: str | None = None
    heartbeat: str | None = None
    pid_start: str | None = None

    def settings(self) -> dict[str, str]:
        """Parameters and overrides as one ``key -> value`` map (overrides win)."""
        merged = {str(k): str(v) for k, v in self.params.items()}
        merged.update(overrides_as_dict(self.overrides))
        return merged



def records(conn: sqlite3.Connection, sql: str, args: list) -> list[RunRecord]:
    rows = conn.execute(sql, args).fetchall()
    if not rows:
        return []
    metrics: dict[str, dict[str, float]] = {}
    ids = [row["id"] for row in rows]
    for start in range(0, len(ids), 500):
        chunk = ids[start:start + 500]
        query = (f"SELECT run_id, name, value FROM metrics WHERE run_id IN "
                 f"({', '.join('?' * len(chunk))}) ORDER BY rowid")
        for run_id, name, value in conn.execute(query, chunk):
            metrics.setdefault(run_id, {})[name] = math.nan if value is None else float(value)
    return [record(row, metrics.get(row["id"], {})) for row in rows]


def record(row: sqlite3.Row, metrics: dict[str, float]) -> RunRecord:
    stored = row["status"]
    path = row["path"]
    keys = row.keys()
    pid, host = (row["pid"], row["host"]) if "pid" in keys else (None, None)
    pid_start, beat = (row["pid_start"], row["heartbeat"]) if "pid" in keys else (None, None)
    status = stored
    if stored == "running" and not run_alive(pid, host, pid_start, beat):
        status = DIED
    elif path and not os.path.exists(path):
        status = MISSING
    return RunRecord(
        id=row["id"], experiment=row["experiment"], overrides=list(json.loads(row["overrides"])),
        params=dict(json.loads(row["params"])), status=status, start_time=row["start_time"],
        end_time=row["end_time"], wall_time_s=row["wall_time_s"], metrics=metrics, path=path,
        git_commit=row["git_commit"], error=row["error"], recorded_status=stored,
        pid=pid, host=host, heartbeat=beat, pid_start=pid_start,
    )
