"""``executor=dask_slurm``: the per-patch work of a run on Dask workers that are SLURM jobs.

A ``dask_jobqueue.SLURMCluster`` is started by the run: its scheduler runs in the run's
process (on the login or head node), and ``n_jobs`` batch jobs (``sbatch``), each of
``cores`` cores and ``memory``, run ``processes`` Dask workers. The jobs are cancelled when
the run ends. :meth:`DaskSlurmExecutor.job_script` is the script each job runs, for checking
before anything is submitted (``pointatlas executor=dask_slurm ... --cfg job`` shows the
settings; the README shows a whole session).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import ClassVar, List, Optional

from pointatlas.constraints import Interval, Types
from pointatlas.errors import ConfigError
from pointatlas.stores_config import stores_config

from .dask_executor import DaskExecutor, require_distributed


@stores_config
class DaskSlurmExecutor(DaskExecutor):
    """Per-patch tasks on Dask workers submitted as SLURM jobs (dask-jobqueue)."""

    @dataclass
    class Config:
        n_jobs: int = 2                   # SLURM jobs (each one sbatch allocation)
        cores: int = 8                    # cores per job (--cpus-per-task)
        processes: int = 1                # Dask worker processes per job (threads: cores /
        #                                   processes each)
        memory: str = "16GiB"             # memory per job (--mem)
        walltime: str = "01:00:00"        # per job (-t), HH:MM:SS
        queue: Optional[str] = None       # partition (-p)
        account: Optional[str] = None     # account to charge (-A)
        job_extra_directives: List[str] = field(default_factory=list)  # more #SBATCH lines,
        #                                   e.g. ['--constraint=cpu', '--qos=normal']
        job_script_prologue: List[str] = field(default_factory=list)   # shell lines before the
        #                                   worker starts, e.g. ['module load python',
        #                                   'source ~/venvs/pointatlas/bin/activate']
        interface: Optional[str] = None   # network interface of the workers, e.g. 'ib0'
        python: Optional[str] = None      # the workers' python (None: this run's, which
        #                                   must then be on a file system the nodes share)
        connect_timeout: float = 600.0    # s to wait for the first worker (queue time)
        tasks_per_thread: int = 4         # batches per worker thread and map
        retries: int = 0                  # re-runs of a task that raised

        parameter_constraints: ClassVar[dict[str, list]] = {
            "n_jobs": [Interval(int, 1, None)],
            "cores": [Interval(int, 1, None)],
            "processes": [Interval(int, 1, None)],
            "memory": [Types(str)],
            "walltime": [Types(str)],
            "queue": [Types(str), None],
            "account": [Types(str), None],
            "interface": [Types(str), None],
            "python": [Types(str), None],
            "connect_timeout": [Interval(float, 0, None, closed="neither")],
            "tasks_per_thread": [Interval(int, 1, None)],
            "retries": [Interval(int, 0, None)],
        }

    description: ClassVar[str] = "Per-patch tasks on Dask workers run as SLURM jobs."
    scheduler_address = None

    def check_config(self) -> None:
        if self.processes > self.cores:
            raise ConfigError(f"executor.processes={self.processes} is more than executor.cores="
                              f"{self.cores}: each worker process needs a core. Pass e.g. "
                              "executor.processes=1.")
        parts = self.walltime.split(":")
        if not (1 <= len(parts) <= 4 and all(p.isdigit() for p in parts)):
            raise ConfigError(f"executor.walltime={self.walltime!r} is invalid: write it as "
                              "SLURM does, HH:MM:SS (e.g. executor.walltime=02:00:00).")

    def _cluster_kwargs(self) -> dict:
        threads = max(1, self.cores // self.processes)
        return dict(
            cores=self.cores, processes=self.processes, memory=self.memory,
            walltime=self.walltime, queue=self.queue, account=self.account,
            job_extra_directives=list(self.job_extra_directives),
            job_script_prologue=[f"export NUMBA_NUM_THREADS={threads}",
                                 *self.job_script_prologue],
            interface=self.interface, silence_logs=logging.WARNING,
            **({"python": self.python} if self.python else {}))

    def _start_cluster(self):
        import shutil

        require_distributed()
        if shutil.which("sbatch") is None:
            raise ConfigError("executor=dask_slurm submits its workers with sbatch, which is not "
                              "on the PATH here: run on a SLURM login node, or use "
                              "executor=dask (a local cluster or executor.scheduler_address).")
        try:
            from dask_jobqueue import SLURMCluster
        except ImportError:
            raise ConfigError("executor=dask_slurm needs dask-jobqueue, which is not "
                              "installed: pip install 'pointatlas[distributed]'.") from None
        cluster = SLURMCluster(**self._cluster_kwargs())
        cluster.scale(jobs=self.n_jobs)
        return cluster

    def job_script(self) -> str:
        """The batch script each SLURM job runs (nothing is submitted)."""
        require_distributed()
        from dask_jobqueue import SLURMCluster

        with SLURMCluster(**self._cluster_kwargs()) as cluster:
            return cluster.job_script()
