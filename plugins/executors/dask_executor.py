"""``executor=dask``: the per-patch work of a run on a Dask cluster (dask.distributed).

The run starts a ``LocalCluster`` (``n_workers`` processes of ``threads_per_worker``
threads) or connects to the scheduler at ``scheduler_address``; :meth:`DaskExecutor.map`
then sends the items of a map (the atlas's patches, the assembler's point blocks) as tasks:

- the ``shared`` data (the point array, the partition of unity) is scattered to every worker
  once (``broadcast``), the items in ``tasks_per_thread`` × (worker threads) contiguous
  batches of about equal cost, each scattered and copied to a second worker: no task
  carries its data in the task graph (no "large graph" warning);
- a worker that dies (``kill -9``) has its tasks re-run by Dask elsewhere; batches whose
  only copy of scattered data it held (the scheduler's active memory manager drops extra
  replicas) are scattered and submitted again. The functions are pure, so the results are
  the same;
- a task that raises becomes one :class:`~pointatlas.executor.TaskError` naming the item
  (``patch 17``) and the worker with its message;
- progress (tasks done of all, rate, ETA) is logged as the tasks finish.

On connecting, the workers' pointatlas version is compared with this one (refused if they
differ: the pickled functions are this version's).
"""
from __future__ import annotations

import itertools
import logging
from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.constraints import Interval, Types
from pointatlas.errors import ConfigError, InputError, PointatlasError
from pointatlas.executor import TaskError, balanced_ranges
from pointatlas.stores_config import stores_config

log = logging.getLogger("pointatlas.executor")
_TOKENS = itertools.count()
#: how many times the batches whose scattered data a lost worker held are sent again
MAX_RESUBMISSIONS = 3


def require_distributed():
    """The ``distributed`` module, or a ConfigError naming the extra to install."""
    try:
        import distributed
    except ImportError:
        raise ConfigError(
            "executor=dask needs Dask distributed, which is not installed: pip install "
            "'pointatlas[distributed]' (or use executor=local).") from None
    return distributed


def run_batch(fn, shared, payload):
    """On a worker: ``fn(shared, item)`` for the batch's items; a failure names the item."""
    items, labels = payload
    out = []
    for item, label in zip(items, labels):
        try:
            out.append(fn(shared, item))
        except Exception as exc:  # noqa: BLE001 — re-raised as one line with where it happened
            where = _worker_address()
            what = str(exc) if isinstance(exc, PointatlasError) else f"{type(exc).__name__}: {exc}"
            raise TaskError(f"{label} failed on worker {where}: {what}") from None
    return out


def _worker_address() -> str:
    try:
        from distributed import get_worker

        return get_worker().address
    except Exception:  # noqa: BLE001 — not on a worker (tests calling run_batch directly)
        return "(this process)"


def worker_version() -> str:
    """The pointatlas version a worker imports (run on each worker at connection)."""
    import pointatlas

    return pointatlas.__version__


@stores_config
class DaskExecutor:
    """Per-patch tasks on a Dask cluster (see the module docstring)."""

    @dataclass
    class Config:
        scheduler_address: Optional[str] = None  # e.g. tcp://10.0.0.5:8786; None: a
        #                                          LocalCluster started (and stopped) by the run
        n_workers: int = 2                # LocalCluster: worker processes
        threads_per_worker: int = 1       # LocalCluster: threads (and numba threads) each
        memory_limit: str = "auto"        # LocalCluster: per worker, e.g. '4GiB'
        connect_timeout: float = 10.0     # s to wait for the scheduler (and the workers)
        tasks_per_thread: int = 4         # batches per worker thread and map
        retries: int = 0                  # re-runs of a task that raised (a lost worker's
        #                                   tasks are re-run by Dask regardless)

        parameter_constraints: ClassVar[dict[str, list]] = {
            "scheduler_address": [Types(str), None],
            "n_workers": [Interval(int, 1, None)],
            "threads_per_worker": [Interval(int, 1, None)],
            "memory_limit": [Types(str)],
            "connect_timeout": [Interval(float, 0, None, closed="neither")],
            "tasks_per_thread": [Interval(int, 1, None)],
            "retries": [Interval(int, 0, None)],
        }

    description: ClassVar[str] = "Per-patch tasks on a Dask cluster (LocalCluster or a scheduler)."
    distributed: ClassVar[bool] = True

    # -- connection ----------------------------------------------------------------------
    def _start_cluster(self):
        """The cluster this run starts (None: connect to ``scheduler_address``)."""
        from distributed import LocalCluster

        return LocalCluster(
            n_workers=self.n_workers, threads_per_worker=self.threads_per_worker,
            processes=True, memory_limit=self.memory_limit, dashboard_address=":0",
            silence_logs=logging.WARNING,
            env={"NUMBA_NUM_THREADS": str(self.threads_per_worker)})

    def client(self):
        """The Dask client, connected (and the version of the workers checked) on first use."""
        if getattr(self, "_client", None) is not None:
            return self._client
        require_distributed()
        from distributed import Client

        self._cluster = None
        for name in ("distributed", "dask_jobqueue"):  # their INFO lines drown the run's log
            logging.getLogger(name).setLevel(logging.WARNING)
        if self.scheduler_address:
            try:
                self._client = Client(self.scheduler_address,
                                      timeout=f"{self.connect_timeout}s")
            except (OSError, TimeoutError) as exc:
                raise InputError(
                    f"no Dask scheduler answers at {self.scheduler_address} (after "
                    f"{self.connect_timeout:g} s: {type(exc).__name__}). Start one with "
                    "`dask scheduler` and workers with `dask worker <address>`, or leave "
                    "executor.scheduler_address unset for a local cluster.") from None
        else:
            self._cluster = self._start_cluster()
            self._client = Client(self._cluster)
        try:
            self._check_workers()
        except BaseException:
            self.close()
            raise
        return self._client

    def n_threads(self) -> int:
        """Threads of all the workers (the parts a map is cut in are a multiple of it)."""
        return max(1, sum(self.client().nthreads().values()))

    def start(self) -> None:
        """Connect now (the run calls this first: an unreachable scheduler or workers of
        another version stop the run before any work)."""
        self.client()

    def _check_workers(self) -> None:
        import pointatlas

        client = self._client
        try:
            client.wait_for_workers(1, timeout=self.connect_timeout)
        except (TimeoutError, OSError):
            raise InputError(
                f"the Dask scheduler at {client.scheduler.address} has no workers (waited "
                f"{self.connect_timeout:g} s). Start some with `dask worker "
                f"{client.scheduler.address}`.") from None
        versions = client.run(worker_version)
        other = {a: v for a, v in versions.items() if v != pointatlas.__version__}
        if other:
            addr, v = sorted(other.items())[0]
            raise ConfigError(
                f"{len(other)} of {len(versions)} Dask workers run pointatlas {v} (e.g. "
                f"{addr}), this run pointatlas {pointatlas.__version__}: install the same "
                "version on the workers (their environment must match the client's).")
        threads = sum(client.nthreads().values())
        log.info("dask: %d workers, %d threads, scheduler %s", len(versions), threads,
                 client.scheduler.address)

    def close(self) -> None:
        client, cluster = getattr(self, "_client", None), getattr(self, "_cluster", None)
        self._client, self._cluster, self._shared = None, None, {}
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()

    # -- work ----------------------------------------------------------------------------
    def _scatter_shared(self, shared, key):
        cache = getattr(self, "_shared", None)
        if cache is None:
            cache = self._shared = {}
        if key is not None and key in cache:
            return cache[key]
        [future] = self._client.scatter([shared], broadcast=True, hash=False)
        if key is not None:
            cache.clear()          # one shared object kept at a time (e.g. one assembler)
            cache[key] = future
        return future

    def map(self, fn, items, *, shared=None, shared_key=None, desc="tasks", labels=None,
            costs=None, min_tasks=None) -> list:
        """``[fn(shared, item) for item in items]`` as batched tasks on the cluster.

        Scattered data lives on workers: Dask re-runs the tasks of a lost worker, but not
        data whose only copy it held (the scheduler's active memory manager drops the extra
        replicas). Batches cancelled so are scattered and submitted again, up to
        :data:`MAX_RESUBMISSIONS` times; the functions are pure, so the results do not
        change."""
        from distributed import as_completed

        from pointatlas.progress import Progress

        items = list(items)
        if not items:
            return []
        client = self.client()
        labels = list(labels) if labels is not None else [f"item {i}" for i in range(len(items))]
        threads = self.n_threads()
        costs = np.ones(len(items)) if costs is None else np.asarray(costs, dtype=np.float64)
        n_tasks = max(self.tasks_per_thread * threads, int(min_tasks or 0))
        batches = balanced_ranges(costs, min(len(items), n_tasks))
        token = next(_TOKENS)
        results: list = [None] * len(batches)
        pending = list(range(len(batches)))
        bar = Progress(total=len(batches), desc=f"{desc} on dask ({len(items)} items in "
                                                f"{len(batches)} tasks, {threads} threads)",
                       logger=log)
        try:
            for round_ in range(MAX_RESUBMISSIONS + 1):
                pending = self._run_batches(client, fn, shared, shared_key, items, labels,
                                            batches, pending, results, f"{desc}-{token}-"
                                            f"{round_}", desc, bar, as_completed)
                if not pending:
                    break
                log.warning("%s: a lost worker held the only copy of the data of %d tasks: "
                            "sending them again", desc, len(pending))
                self._drop_shared(shared_key)
            else:
                raise TaskError(f"{desc}: workers kept dying with the data of {len(pending)} "
                                f"tasks ({MAX_RESUBMISSIONS} resubmissions); check the "
                                "workers' memory and logs")
        finally:
            bar.close()
        return [r for part in results for r in part]

    def _run_batches(self, client, fn, shared, shared_key, items, labels, batches, pending,
                     results, prefix, desc, bar, as_completed) -> list:
        """Submit the ``pending`` batches and gather them into ``results``; returns those
        cancelled because their scattered data was lost."""
        shared_future = self._scatter_shared(shared, shared_key)
        payloads = client.scatter([(items[batches[i][0]:batches[i][1]],
                                    labels[batches[i][0]:batches[i][1]]) for i in pending],
                                  hash=False)
        if len(client.nthreads()) > 1:
            client.replicate(payloads, n=2)      # fewer lost batches when a worker dies
        futures = [client.submit(run_batch, fn, shared_future, p, pure=False,
                                 retries=self.retries, key=f"{prefix}-{i}")
                   for i, p in zip(pending, payloads)]
        index = {f.key: i for i, f in zip(pending, futures)}
        lost = []
        try:
            for future in as_completed(futures):
                if future.status == "cancelled":
                    lost.append(index[future.key])
                    continue
                if future.status == "error":
                    exc = future.exception()
                    if isinstance(exc, PointatlasError):
                        raise TaskError(f"{desc}: {exc}") from None
                    raise TaskError(f"{desc}: a task failed on the cluster: "
                                    f"{type(exc).__name__}: {exc}") from None
                results[index[future.key]] = future.result()
                client.cancel([future])   # the worker frees its copy of the result now,
                bar.update(1)             # not when the whole map is done
        finally:
            client.cancel([f for f in futures if not f.done()])
            if shared_key is None:
                client.cancel([shared_future])
            client.cancel(payloads)
        return sorted(lost)

    def _drop_shared(self, key) -> None:
        """Forget the cached scattered ``shared`` of ``key`` (its data may be lost)."""
        cache = getattr(self, "_shared", None)
        if cache is not None and key in cache:
            self._client.cancel([cache.pop(key)])
