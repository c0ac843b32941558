"""Where a run's independent per-patch work runs: the executor protocol and the run's executor.

The atlas (embedding, chart and quadrature of each patch; thesis §3, parallelised there with
OpenMP) and the kit's assembly (per block of quadrature points) are maps of one pure function
over independent items. A run chooses where they run with the ``executor`` config group
(``executor=local``: this process and its threads, the default; ``executor=dask``,
``executor=dask_slurm``: a Dask cluster, the ``pointatlas_executors`` plugins). The run
pipeline installs the chosen executor for the duration of the run (:func:`using_executor`);
library code asks :func:`current_executor` and, on a ``distributed`` one, sends its items
there with :meth:`Executor.map`. Without a run (a script that builds an ``Atlas`` itself) the
current executor is :class:`SerialExecutor`, i.e. today's behaviour.

``map(fn, items, shared=...)`` calls ``fn(shared, item)`` for every item and returns the
results in the order of the items. ``shared`` is the data every item needs (the point array,
the partition of unity): a distributed executor sends it once, not once per item. ``fn``
must be a module-level function (it is pickled by reference) and deterministic: the same
items give bit-for-bit the same results wherever they run.
"""
from __future__ import annotations

from contextlib import contextmanager
from typing import Any, Callable, Iterator, Protocol, Sequence

import numpy as np

from .errors import PointatlasError


def balanced_ranges(work: np.ndarray, n_parts: int) -> list[tuple[int, int]]:
    """Contiguous, non-empty index ranges over len(work) items with about equal Σ work (at
    most ``n_parts``; [(0, 0)] for no items): the parts of a map and of the kit's assembly."""
    c = np.cumsum(work, dtype=np.float64)
    total = c[-1] if len(c) else 0.0
    cuts = np.searchsorted(c, total * np.arange(1, n_parts) / n_parts)
    b = np.concatenate([[0], cuts, [len(work)]]).astype(np.int64)
    return [(int(s), int(e)) for s, e in zip(b[:-1], b[1:]) if e > s] or [(0, 0)]


class TaskError(PointatlasError):
    """A task raised on a worker; the message names the item (e.g. the patch) and the worker."""


class Executor(Protocol):
    """Runs ``fn(shared, item)`` for each item; ``distributed``: in other processes."""

    distributed: bool

    def map(self, fn: Callable[[Any, Any], Any], items: Sequence, *, shared: Any = None,
            shared_key: Any = None, desc: str = "tasks",
            labels: Sequence[str] | None = None, costs: Sequence[float] | None = None,
            min_tasks: int | None = None) -> list:
        """``[fn(shared, item) for item in items]``; a distributed executor sends the items
        in contiguous batches of about equal ``costs``, about max(its default, ``min_tasks``)
        of them (items that are each a task's worth of work and data: ``len(items)``)."""

    def close(self) -> None: ...


class SerialExecutor:
    """In this process, one item after the other (each item may use numba's threads)."""

    distributed = False

    def map(self, fn, items, *, shared=None, shared_key=None, desc="tasks", labels=None,
            costs=None, min_tasks=None) -> list:
        out = []
        for i, item in enumerate(items):
            try:
                out.append(fn(shared, item))
            except PointatlasError:
                raise
            except Exception as exc:
                what = labels[i] if labels is not None else f"item {i}"
                raise TaskError(f"{desc}: {what} failed: {type(exc).__name__}: {exc}") from exc
        return out

    def close(self) -> None:
        pass


_CURRENT: list[Executor] = []


def current_executor() -> Executor:
    """The executor of the running run (:func:`using_executor`), else a :class:`SerialExecutor`."""
    return _CURRENT[-1] if _CURRENT else SerialExecutor()


@contextmanager
def using_executor(executor: Executor) -> Iterator[Executor]:
    """Make ``executor`` current inside the block; close it when the block ends."""
    _CURRENT.append(executor)
    try:
        yield executor
    finally:
        _CURRENT.pop()
        executor.close()
