"""Is a recorded run still alive? Process identity, heartbeat, and the test for a dead run.

A run records, when it starts, the identity of its process: PID, host name and the PID's
start time (``/proc/<pid>/stat`` field 22, clock ticks since boot, so a PID reused by another
process is not taken for the run), and refreshes a heartbeat timestamp in the catalog every
:data:`HEARTBEAT_S` seconds while it works. A row still marked ``running`` is *died* when

- on this host: no process with that PID and start time exists;
- on another host (a cluster node): the heartbeat is older than :data:`STALE_S`.

Standard library only.
"""
from __future__ import annotations

import os
import socket
import threading
from datetime import datetime, timezone
from typing import Callable

#: seconds between two heartbeats of a running run
HEARTBEAT_S = 30.0
#: a run on another host whose heartbeat is older than this (s) is taken for dead
STALE_S = 10 * HEARTBEAT_S


def hostname() -> str:
    return socket.gethostname()


def process_start(pid: int) -> str:
    """Start time of process ``pid`` in clock ticks since boot ('' when /proc is absent or the
    process does not exist)."""
    try:
        with open(f"/proc/{int(pid)}/stat", "rb") as fh:
            text = fh.read().decode(errors="replace")
    except OSError:
        return ""
    # the command name (field 2) is in parentheses and may hold spaces: split after it
    fields = text[text.rfind(")") + 2:].split()
    return fields[19] if len(fields) > 19 else ""


def identity() -> dict[str, object]:
    """``{"pid", "host", "pid_start"}`` of the calling process."""
    pid = os.getpid()
    return {"pid": pid, "host": hostname(), "pid_start": process_start(pid)}


def pid_alive(pid: int | None, pid_start: str | None = None) -> bool:
    """Whether a process with this PID (and, when known, this start time) exists here."""
    if pid is None or int(pid) <= 0:
        return False
    if os.path.isdir("/proc"):
        now = process_start(int(pid))
        return bool(now) and (not pid_start or now == pid_start)
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def heartbeat_age_s(heartbeat: str | None, now: datetime | None = None) -> float | None:
    """Seconds since an ISO 8601 heartbeat (None when missing or unreadable)."""
    if not heartbeat:
        return None
    try:
        then = datetime.fromisoformat(heartbeat)
    except ValueError:
        return None
    if then.tzinfo is None:
        then = then.replace(tzinfo=timezone.utc)
    return ((now or datetime.now(timezone.utc)) - then).total_seconds()


def run_alive(pid: int | None, host: str | None, pid_start: str | None,
              heartbeat: str | None) -> bool:
    """Whether a run recorded as running with this identity may still be running.

    Rows written before runs recorded their process (no PID, no heartbeat) are given the
    benefit of the doubt: they stay ``running``.
    """
    if pid is None and not heartbeat:
        return True
    if host == hostname():
        return pid_alive(pid, pid_start)
    age = heartbeat_age_s(heartbeat)
    return age is None or age < STALE_S


class Heartbeat:
    """A daemon thread calling ``beat()`` every ``interval`` seconds until :meth:`stop`.

    Errors of ``beat`` (a locked or broken catalog) are swallowed: a heartbeat is a hint,
    never a reason to stop the run.
    """

    def __init__(self, beat: Callable[[], None], interval: float = HEARTBEAT_S):
        self._beat, self._interval = beat, interval
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name="pointatlas-heartbeat",
                                        daemon=True)

    def _loop(self) -> None:
        while not self._stop.wait(self._interval):
            try:
                self._beat()
            except Exception:  # noqa: BLE001 - see the class docstring
                pass

    def __enter__(self) -> "Heartbeat":
        self._thread.start()
        return self

    def __exit__(self, *exc) -> bool:
        self.stop()
        return False

    def stop(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=5)
