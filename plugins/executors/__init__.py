"""Executors of a run's per-patch work: ``local`` (this process), ``dask`` and ``dask_slurm``."""
