"""Short-lived SQLite connections shared safely by concurrent processes.

Every operation opens its own connection (nothing is held across ``fork``), runs one short
transaction and retries while the database is locked or busy. Standard library only.
"""
from __future__ import annotations

import random
import sqlite3
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator, TypeVar

BUSY_TIMEOUT_S = 60.0
RETRY_DEADLINE_S = 180.0
T = TypeVar("T")


def connect(path: Path) -> sqlite3.Connection:
    """A connection in autocommit mode (transactions are explicit), rows by name."""
    conn = sqlite3.connect(str(path), timeout=BUSY_TIMEOUT_S, isolation_level=None)
    conn.row_factory = sqlite3.Row
    conn.execute(f"PRAGMA busy_timeout={int(BUSY_TIMEOUT_S * 1000)}")
    conn.execute("PRAGMA foreign_keys=ON")
    conn.execute("PRAGMA synchronous=NORMAL")  # safe with WAL; may drop the last commit on power loss
    return conn


@contextmanager
def immediate_transaction(conn: sqlite3.Connection) -> Iterator[sqlite3.Connection]:
    """``BEGIN IMMEDIATE`` ... ``COMMIT``, rolled back on any error."""
    conn.execute("BEGIN IMMEDIATE")
    try:
        yield conn
        conn.execute("COMMIT")
    except BaseException:
        if conn.in_transaction:
            conn.execute("ROLLBACK")
        raise


def retry(attempt: Callable[[], T]) -> T:
    """Call ``attempt`` until it does not fail with 'locked'/'busy' (jittered back-off)."""
    deadline = time.monotonic() + RETRY_DEADLINE_S
    delay = 0.01
    while True:
        try:
            return attempt()
        except sqlite3.OperationalError as exc:
            message = str(exc).lower()
            if ("locked" not in message and "busy" not in message) or time.monotonic() > deadline:
                raise
        time.sleep(delay * (0.5 + random.random()))
        delay = min(delay * 2, 1.0)


def write(path: Path, operation: Callable[[sqlite3.Connection], None]) -> None:
    """Run ``operation`` in one immediate transaction on a fresh connection, with retries."""
    def attempt() -> None:
        conn = connect(path)
        try:
            with immediate_transaction(conn):
                operation(conn)
        finally:
            conn.close()

    retry(attempt)


def read(path: Path, operation: Callable[[sqlite3.Connection], T]) -> T:
    """Run ``operation`` on a fresh connection, with retries."""
    def attempt() -> T:
        conn = connect(path)
        try:
            return operation(conn)
        finally:
            conn.close()

    return retry(attempt)
