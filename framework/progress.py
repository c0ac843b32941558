"""Progress of long work as log lines (count, rate, ETA), drawn by tqdm, and a heartbeat for
long single steps.

Runs log to a file and to the terminal of a batch job, so the bar is not redrawn in place:
each tqdm refresh (at most every ``interval`` s) is one log line, ``desc: i/n (p%) rate ETA``.
The first item is left out of the rate and the ETA (it usually carries numba's JIT
compilation), so the first ETA that is printed is measured on compiled code.
:class:`Heartbeat` logs ``label: still running, … elapsed`` every ``every`` s of a step that
reports nothing itself, so no stage of a run is silent for long.
"""
from __future__ import annotations

import logging
import threading
import time
from collections.abc import Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")
log = logging.getLogger("pointatlas.progress")
BAR_FORMAT = "{desc}: {n_fmt}/{total_fmt} ({percentage:.0f}%) {rate_fmt} ETA {remaining}"
BAR_FORMAT_OPEN = "{desc}: {n_fmt} {rate_fmt} elapsed {elapsed}"


def format_seconds(seconds: float) -> str:
    seconds = max(0.0, float(seconds))
    if seconds < 60:
        return f"{seconds:.1f}s"
    minutes, sec = divmod(int(round(seconds)), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}h{minutes:02d}m{sec:02d}s" if hours else f"{minutes}m{sec:02d}s"


class _LogLines:
    """A file for tqdm whose every refresh becomes one log line (repeats dropped)."""

    def __init__(self, logger: logging.Logger):
        self.logger, self.last = logger, ""

    def write(self, text: str) -> None:
        text = text.replace("\r", "").strip()
        if text and text != self.last:
            self.last = text
            self.logger.info(text)

    def flush(self) -> None:
        pass


class Progress:
    """Count work items and log ``desc: i/n (p%) rate ETA`` at most every ``interval`` s.

    Use as an iterator wrapper (``for x in Progress(items, desc="charts")``) or call
    :meth:`update` by hand. The last line is always logged.
    """

    def __init__(self, iterable: Iterable[T] | None = None, *, total: int | None = None,
                 desc: str = "work", interval: float = 2.0, logger: logging.Logger | None = None):
        from tqdm import tqdm

        if total is None and iterable is not None and hasattr(iterable, "__len__"):
            total = len(iterable)  # type: ignore[arg-type]
        self.iterable, self.total, self.desc = iterable, total, desc
        self.lines = _LogLines(logger or log)
        self.bar = tqdm(total=total, desc=desc, file=self.lines, mininterval=interval,
                        miniters=1, smoothing=0, ascii=True, leave=True,
                        bar_format=BAR_FORMAT if total else BAR_FORMAT_OPEN)
        self._compiled = False

    @property
    def count(self) -> int:
        return int(self.bar.n)

    def line(self) -> str:
        return self.lines.last

    def update(self, n: int = 1) -> None:
        if not self._compiled:  # time the rest from here: the first item carries the JIT
            self._compiled = True
            self.bar.n += n
            self.bar.initial = self.bar.n
            self.bar.start_t = self.bar.last_print_t = self.bar._time()
            self.bar.refresh()
        else:
            self.bar.update(n)
        if self.total and self.bar.n >= self.total:
            self.close()

    def close(self) -> None:
        self.bar.close()  # logs the final line once (tqdm's leave=True)

    def __iter__(self) -> Iterator[T]:
        try:
            for item in self.iterable or ():
                yield item
                self.update()
        finally:
            self.close()


class Heartbeat:
    """Context manager: log ``label: still running, <elapsed> elapsed`` every ``every`` s
    until the block ends (a daemon thread; nothing is logged for a block shorter than that)."""

    def __init__(self, label: str, logger: logging.Logger | None = None, every: float = 10.0):
        self.label, self.log, self.every = label, logger or log, every
        self._stop = threading.Event()

    def _beat(self) -> None:
        while not self._stop.wait(self.every):
            self.log.info("%s: still running, %s elapsed", self.label,
                          format_seconds(time.perf_counter() - self.t0))

    def __enter__(self):
        self.t0 = time.perf_counter()
        self._thread = threading.Thread(target=self._beat, daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc) -> bool:
        self._stop.set()
        self._thread.join(timeout=1.0)
        return False


__all__ = ["Progress", "Heartbeat", "format_seconds"]
