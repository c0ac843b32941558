"""The run catalog: one SQLite row per run, finished or failed, for experiment tracking.

The catalog lives at ``<outputs_root>/catalog.sqlite`` (:func:`catalog_path`). The run pipeline
calls :meth:`Catalog.start` when a run begins, :meth:`Catalog.finish` when it ends, and
:meth:`Catalog.record_failure` for a run that failed before it could start (a bad config).
``pointatlas-runs`` (:mod:`pointatlas.runs_cli`) reads it back with :meth:`Catalog.runs` and
:meth:`Catalog.get`.

Concurrency: the jobs of a multirun (joblib processes, submitit jobs) write to the same file at
once. Every operation opens its own short-lived connection (nothing is held across ``fork``),
runs one short transaction, and retries on "database is locked"; the journal is WAL with a
60 s busy timeout. WAL needs a local filesystem (or one with working POSIX locks); on NFS put
the outputs root on local disk or expect lock errors.

Schema (version :data:`SCHEMA_VERSION`): ``runs`` (one row per run; overrides and params as
JSON text; the process that runs it: ``pid``, ``host``, ``pid_start`` and the ``heartbeat`` it
refreshes, :mod:`pointatlas.liveness`), ``metrics`` (run_id, name, value; NULL stores NaN)
and ``schema_version``. A row left ``running`` by a process that is gone reads as ``died``.
Standard library only, so importing this module stays fast.
"""
from __future__ import annotations

import json
import math
import os
import sqlite3
from datetime import datetime
from pathlib import Path
from typing import Callable, Iterable, TypeVar

from .errors import ConfigError, InputError, SchemaError
from .catalog_rows import DIED, MISSING, RunRecord, records as _records  # noqa: F401
from .sqlite_access import connect, immediate_transaction, read, retry, write
from .run_filters import (  # noqa: F401 - re-exported
    METRIC_SYNTAX, WHERE_SYNTAX, MetricFilter, WhereFilter, overrides_as_dict, parse_metric,
    parse_where,
)

#: Version of the catalog schema this module writes and reads.
SCHEMA_VERSION = 2
#: File name of the catalog inside the outputs root.
CATALOG_FILENAME = "catalog.sqlite"
#: Statuses stored in the catalog; "missing" is computed when the run directory is gone, and
#: "died" for a run recorded as running whose process no longer exists. "rejected": the command
#: line was refused at start-up (a typo, a bad value) before any work; such rows are hidden
#: unless asked for (``status="rejected"`` or ``include_rejected=True``).
STATUSES = ("running", "completed", "completed_with_warnings", "failed", "rejected")
REJECTED = "rejected"
_FINISHED = ("completed", "completed_with_warnings", "failed", REJECTED)


_SCHEMA = """
CREATE TABLE IF NOT EXISTS schema_version (version INTEGER NOT NULL);
CREATE TABLE IF NOT EXISTS runs (
    id TEXT PRIMARY KEY,
    experiment TEXT NOT NULL,
    overrides TEXT NOT NULL DEFAULT '[]',
    params TEXT NOT NULL DEFAULT '{}',
    status TEXT NOT NULL,
    start_time TEXT,
    end_time TEXT,
    wall_time_s REAL,
    path TEXT,
    git_commit TEXT NOT NULL DEFAULT '',
    error TEXT,
    pid INTEGER,
    host TEXT,
    pid_start TEXT,
    heartbeat TEXT
);
CREATE TABLE IF NOT EXISTS metrics (
    run_id TEXT NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
    name TEXT NOT NULL,
    value REAL,
    PRIMARY KEY (run_id, name)
);
CREATE INDEX IF NOT EXISTS runs_experiment ON runs(experiment);
CREATE INDEX IF NOT EXISTS runs_start_time ON runs(start_time);
CREATE INDEX IF NOT EXISTS metrics_name ON metrics(name);
"""

def _add_process_columns(conn: sqlite3.Connection) -> None:
    """1 -> 2: the process running each run (pid, host, pid_start) and its heartbeat."""
    have = {row[1] for row in conn.execute("PRAGMA table_info(runs)")}
    for column, kind in (("pid", "INTEGER"), ("host", "TEXT"), ("pid_start", "TEXT"),
                         ("heartbeat", "TEXT")):
        if column not in have:
            conn.execute(f"ALTER TABLE runs ADD COLUMN {column} {kind}")


#: Migrations from version N to N+1 (executed inside one transaction).
_MIGRATIONS: dict[int, Callable[[sqlite3.Connection], None]] = {1: _add_process_columns}

T = TypeVar("T")


def catalog_path(outputs_root: str | Path) -> Path:
    """Path of the catalog file under an outputs root: ``<outputs_root>/catalog.sqlite``."""
    return Path(outputs_root) / CATALOG_FILENAME


# ----------------------------------------------------------------------------- catalog


class Catalog:
    """The SQLite run catalog at ``path`` (created with its schema and parent dirs if missing)."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        retry(self._init_schema)

    def __repr__(self) -> str:
        return f"Catalog({str(self.path)!r})"

    # -- writing ---------------------------------------------------------------------------

    def start(self, *, run_id: str, experiment: str, overrides: list[str], path: str | None,
              git_commit: str, start_time: str, params: dict[str, str] | None = None,
              process: dict | None = None) -> None:
        """Record a run that has started (status "running"); re-using an id replaces the run.

        ``process``: ``{"pid", "host", "pid_start"}`` of the process running it
        (:func:`pointatlas.liveness.identity`), so that a killed run reads as "died".
        """
        process = process or {}
        row = {
            "id": _check_id(run_id), "experiment": str(experiment),
            "overrides": _json_list(overrides), "params": _json_params(params),
            "status": "running", "start_time": start_time, "end_time": None,
            "wall_time_s": None, "path": _abs_path(path), "git_commit": git_commit or "",
            "error": None, "pid": process.get("pid"), "host": process.get("host"),
            "pid_start": process.get("pid_start"),
            "heartbeat": start_time if process else None,
        }
        self._write(lambda conn: _upsert(conn, row))

    def forget(self, run_id: str) -> None:
        """Delete a run's row and its metrics."""
        self._write(lambda conn: conn.execute("DELETE FROM runs WHERE id=?", (run_id,)))

    def heartbeat(self, run_id: str, time: str) -> None:
        """Refresh the heartbeat of a running run (ISO 8601 time)."""
        self._write(lambda conn: conn.execute(
            "UPDATE runs SET heartbeat=? WHERE id=? AND status='running'", (time, run_id)))

    def finish(self, run_id: str, *, status: str, end_time: str, wall_time_s: float,
               metrics: dict[str, float], error: str | None = None) -> None:
        """Record the end of a started run: status ("completed"/"failed"/"rejected"), time and
        metrics."""
        if status not in _FINISHED:
            raise ConfigError(f"finish status {status!r} is invalid: use one of "
                              f"{', '.join(_FINISHED)}")
        values = _metric_rows(metrics)

        def write(conn: sqlite3.Connection) -> None:
            cursor = conn.execute(
                "UPDATE runs SET status=?, end_time=?, wall_time_s=?, error=? WHERE id=?",
                (status, end_time, _float_or_none(wall_time_s), error, run_id),
            )
            if cursor.rowcount == 0:
                raise InputError(f"run {run_id!r} is not in the catalog {self.path}: "
                                 "call Catalog.start before Catalog.finish")
            conn.execute("DELETE FROM metrics WHERE run_id=?", (run_id,))
            conn.executemany("INSERT INTO metrics (run_id, name, value) VALUES (?, ?, ?)",
                             [(run_id, name, value) for name, value in values])

        self._write(write)

    def record_failure(self, *, run_id: str, experiment: str, overrides: list[str],
                       path: str | None, git_commit: str, start_time: str, end_time: str,
                       error: str) -> None:
        """Record a run that failed before it started (e.g. a bad config) as "failed"."""
        row = {
            "id": _check_id(run_id), "experiment": str(experiment),
            "overrides": _json_list(overrides), "params": "{}", "status": "failed",
            "start_time": start_time, "end_time": end_time,
            "wall_time_s": _elapsed_s(start_time, end_time), "path": _abs_path(path),
            "git_commit": git_commit or "", "error": error,
        }
        self._write(lambda conn: _upsert(conn, row))

    # -- reading ---------------------------------------------------------------------------

    def runs(self, *, experiment: str | None = None, status: str | None = None,
             where: Iterable[str] = (), metric: Iterable[str] = (),
             limit: int | None = None, include_rejected: bool = False) -> list[RunRecord]:
        """Runs matching every filter, oldest first (``limit``: keep only the newest N).
        Command lines rejected at start-up are left out unless ``status="rejected"`` or
        ``include_rejected``.

        ``status`` may be "missing" (the computed status of runs whose directory is gone).
        ``where``: ``key=value`` strings; ``metric``: ``name<op>value`` thresholds.
        Bad filter syntax raises :class:`ConfigError`.
        """
        if isinstance(where, str):
            where = [where]
        if isinstance(metric, str):
            metric = [metric]
        where_filters = [parse_where(text) for text in where]
        metric_filters = [parse_metric(text) for text in metric]
        if status is not None and status not in (*STATUSES, MISSING, DIED):
            raise ConfigError(f"status {status!r} is invalid: use one of "
                              f"{', '.join((*STATUSES, MISSING, DIED))}")
        if limit is not None and limit < 0:
            raise ConfigError(f"limit {limit} is invalid: use a non-negative integer")
        sql, args = "SELECT * FROM runs", []
        if experiment is not None:
            sql, args = sql + " WHERE experiment=?", [experiment]
        sql += " ORDER BY start_time, id"
        records = self._read(lambda conn: _records(conn, sql, args))
        selected = [
            r for r in records
            if (status is None or r.status == status)
            and (r.status != REJECTED or include_rejected or status == REJECTED)
            and all(f.matches(r) for f in where_filters)
            and all(f.matches(r) for f in metric_filters)
        ]
        if limit is not None:
            selected = selected[len(selected) - limit:] if limit else []
        return selected

    def get(self, run_id: str) -> RunRecord:
        """The run with this id, or with this unique id prefix; :class:`InputError` otherwise."""
        run_id = str(run_id).strip()
        if not run_id:
            raise InputError("empty run id: pass a run id or a unique prefix (see `pointatlas-runs list`)")

        def lookup(conn: sqlite3.Connection) -> list[RunRecord]:
            exact = _records(conn, "SELECT * FROM runs WHERE id=?", [run_id])
            if exact:
                return exact
            return _records(conn, "SELECT * FROM runs WHERE substr(id, 1, ?)=? ORDER BY id LIMIT 6",
                            [len(run_id), run_id])

        found = self._read(lookup)
        if not found:
            raise InputError(f"no run with id or prefix {run_id!r} in {self.path}: "
                             "see `pointatlas-runs list`")
        if len(found) > 1:
            shown = ", ".join(r.id for r in found[:5]) + (", ..." if len(found) > 5 else "")
            raise InputError(f"run id prefix {run_id!r} is ambiguous ({shown}): give more characters")
        return found[0]

    def ids(self) -> list[str]:
        """Every run id in the catalog (for shortest-unique-prefix display)."""
        return self._read(lambda conn: [row[0] for row in conn.execute("SELECT id FROM runs")])

    # -- plumbing --------------------------------------------------------------------------

    def _init_schema(self) -> None:
        conn = connect(self.path)
        try:
            if _current_version(conn) == SCHEMA_VERSION:
                return  # ready: no write needed (works on a read-only copy too)
            if conn.execute("PRAGMA journal_mode").fetchone()[0].lower() != "wal":
                conn.execute("PRAGMA journal_mode=WAL")
            with immediate_transaction(conn):
                for statement in filter(str.strip, _SCHEMA.split(";")):
                    conn.execute(statement)
                version = conn.execute("SELECT MAX(version) FROM schema_version").fetchone()[0]
                if version is None:
                    conn.execute("INSERT INTO schema_version (version) VALUES (?)", (SCHEMA_VERSION,))
                elif version > SCHEMA_VERSION:
                    raise SchemaError(f"catalog {self.path} has schema version {version}, newer "
                                      f"than the {SCHEMA_VERSION} this pointatlas reads: upgrade "
                                      "pointatlas")
                else:
                    while version < SCHEMA_VERSION:
                        _MIGRATIONS[version](conn)
                        version += 1
                    conn.execute("UPDATE schema_version SET version=?", (SCHEMA_VERSION,))
        finally:
            conn.close()

    def _write(self, operation: Callable[[sqlite3.Connection], None]) -> None:
        write(self.path, operation)

    def _read(self, operation: Callable[[sqlite3.Connection], T]) -> T:
        return read(self.path, operation)


# ----------------------------------------------------------------------------- helpers


def _current_version(conn: sqlite3.Connection) -> int | None:
    exists = conn.execute(
        "SELECT 1 FROM sqlite_master WHERE type='table' AND name='schema_version'").fetchone()
    if not exists:
        return None
    return conn.execute("SELECT MAX(version) FROM schema_version").fetchone()[0]


def _upsert(conn: sqlite3.Connection, row: dict) -> None:
    """Insert or replace the run row and drop its old metrics (a re-used id starts afresh)."""
    columns = list(row)
    updates = ", ".join(f"{c}=excluded.{c}" for c in columns if c != "id")
    conn.execute(
        f"INSERT INTO runs ({', '.join(columns)}) VALUES ({', '.join('?' * len(columns))}) "
        f"ON CONFLICT(id) DO UPDATE SET {updates}",
        [row[c] for c in columns],
    )
    conn.execute("DELETE FROM metrics WHERE run_id=?", (row["id"],))


def _check_id(run_id: str) -> str:
    if not isinstance(run_id, str) or not run_id.strip():
        raise ConfigError(f"run id {run_id!r} is invalid: use a non-empty string")
    return run_id


def _json_list(items: Iterable[str] | None) -> str:
    return json.dumps([str(item) for item in (items or [])])


def _json_params(params: dict[str, str] | None) -> str:
    return json.dumps({str(k): str(v) for k, v in (params or {}).items()}, sort_keys=True)


def _abs_path(path: str | os.PathLike | None) -> str | None:
    return None if path is None or str(path) == "" else os.path.abspath(os.fspath(path))


def _float_or_none(value: float | None) -> float | None:
    if value is None:
        return None
    value = float(value)
    return None if math.isnan(value) else value


def _metric_rows(metrics: dict[str, float] | None) -> list[tuple[str, float | None]]:
    rows = []
    for name, value in (metrics or {}).items():
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise ConfigError(f"metric {name!r} = {value!r} is not a number: metrics must be "
                              "floats") from None
        rows.append((str(name), None if math.isnan(number) else number))
    return rows


def _elapsed_s(start_time: str | None, end_time: str | None) -> float | None:
    try:
        return (datetime.fromisoformat(end_time) - datetime.fromisoformat(start_time)).total_seconds()
    except (TypeError, ValueError):
        return None
