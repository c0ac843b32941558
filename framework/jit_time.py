"""Time spent compiling numba functions, so stage timings can leave it out.

The first call of a numba function compiles it (or loads it from the cache), which can take
seconds and lands in whichever stage calls it first: a sweep's first run then shows the
compilation as, say, "partition" time. :func:`compile_seconds` is the total wall time of
numba's ``numba:compile`` events (outermost only: a compile that triggers another counts
once) in this process since :func:`start` was first called; a timer subtracts the growth of
this total over its block (:class:`StageTimer`).
"""
from __future__ import annotations

import threading
import time

_lock = threading.Lock()
_state = {"total": 0.0, "installed": False}
_local = threading.local()


def start() -> None:
    """Listen to numba's compile events (once per process; a no-op without numba)."""
    with _lock:
        if _state["installed"]:
            return
        _state["installed"] = True
    try:
        from numba.core import event
    except ImportError:  # pragma: no cover - numba is a dependency
        return

    class _Compiles(event.Listener):
        def on_start(self, ev) -> None:
            depth = getattr(_local, "depth", 0)
            if depth == 0:
                _local.t0 = time.perf_counter()
            _local.depth = depth + 1

        def on_end(self, ev) -> None:
            _local.depth = getattr(_local, "depth", 1) - 1
            if _local.depth == 0:
                with _lock:
                    _state["total"] += time.perf_counter() - _local.t0

    event.register("numba:compile", _Compiles())


def compile_seconds() -> float:
    """Wall time spent compiling numba functions in this process so far (s)."""
    start()
    return _state["total"]


class StageTimer:
    """Context manager adding a block's wall time less its numba compilation to
    ``times[key]`` and the compilation to ``compile_times[key]`` (when given)."""

    def __init__(self, times: dict, key: str, compile_times: dict | None = None):
        self.times, self.key, self.compile_times = times, key, compile_times

    def __enter__(self):
        self.c0, self.t0 = compile_seconds(), time.perf_counter()
        return self

    def __exit__(self, *exc) -> bool:
        compiling = compile_seconds() - self.c0
        wall = time.perf_counter() - self.t0
        self.times[self.key] = self.times.get(self.key, 0.0) + max(wall - compiling, 0.0)
        if self.compile_times is not None:
            self.compile_times[self.key] = self.compile_times.get(self.key, 0.0) + compiling
        return False


__all__ = ["start", "compile_seconds", "StageTimer"]
