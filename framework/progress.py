"""Progress of long work as periodic log lines with count, rate and ETA."""
from __future__ import annotations

import logging
import time
from collections.abc import Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")
log = logging.getLogger("pointatlas.progress")


def format_seconds(seconds: float) -> str:
    seconds = max(0.0, float(seconds))
    if seconds < 60:
        return f"{seconds:.1f}s"
    minutes, sec = divmod(int(round(seconds)), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}h{minutes:02d}m{sec:02d}s" if hours else f"{minutes}m{sec:02d}s"


class Progress:
    """Count work items and log ``desc: i/n (p%) rate/s ETA`` at most every ``interval`` s.

    Use as an iterator wrapper (``for x in Progress(items, desc="charts")``) or call
    :meth:`update` by hand. The last line is always logged.
    """

    def __init__(self, iterable: Iterable[T] | None = None, *, total: int | None = None,
                 desc: str = "work", interval: float = 2.0, logger: logging.Logger | None = None,
                 clock=time.monotonic):
        self.iterable = iterable
        if total is None and iterable is not None and hasattr(iterable, "__len__"):
            total = len(iterable)  # type: ignore[arg-type]
        self.total, self.desc, self.interval = total, desc, interval
        self.log = logger or log
        self.clock = clock
        self.count = 0
        self.start = self.last = clock()

    def line(self) -> str:
        elapsed = self.clock() - self.start
        rate = self.count / elapsed if elapsed > 0 else float("inf")
        if self.total:
            eta = (self.total - self.count) / rate if rate > 0 else float("inf")
            return (f"{self.desc}: {self.count}/{self.total} ({100 * self.count / self.total:.0f}%) "
                    f"{rate:.3g}/s ETA {format_seconds(eta)}")
        return f"{self.desc}: {self.count} {rate:.3g}/s elapsed {format_seconds(elapsed)}"

    def update(self, n: int = 1) -> None:
        self.count += n
        now = self.clock()
        if now - self.last >= self.interval or (self.total and self.count >= self.total):
            self.last = now
            self.log.info(self.line())

    def __iter__(self) -> Iterator[T]:
        for item in self.iterable or ():
            yield item
            self.update()
