"""What became of each job of a sweep, and how to rerun the ones that did not finish.

A multirun whose worker process is killed (``kill -9``, the out-of-memory killer) is aborted
by the launcher (joblib's ``TerminatedWorkerError``), and a job that fails is recorded as
failed while the others go on. Either way the user needs to know which runs did not finish
and how to rerun just those. :class:`SweepGuard` is a Hydra callback (``hydra.callbacks`` in
``conf/config.yaml``) that, when a multirun starts, writes the list of its jobs to
``<sweep dir>/jobs.json``; :func:`unfinished_jobs` compares that list with the
``results.nc`` files the jobs wrote, and :func:`summary` turns the difference into the exit
message of ``pointatlas -m`` with one rerun command per job.
"""
from __future__ import annotations

import json
import shlex
from pathlib import Path
from typing import Any

JOBS_FILE = "jobs.json"
#: the sweep directory and job list of the multirun started in this process
CURRENT: dict[str, Any] = {}


def job_overrides(task_overrides: list[str], sweeper_params: dict | None) -> list[list[str]]:
    """The override list of every job, in job order, as Hydra's basic sweeper expands them
    (the sweeper's ``params`` first, then the command line)."""
    from hydra._internal.core_plugins.basic_sweeper import BasicSweeper
    from hydra.core.override_parser.overrides_parser import OverridesParser

    arguments = [f"{k}={v}" for k, v in (sweeper_params or {}).items()] + list(task_overrides)
    parsed = OverridesParser.create().parse_overrides(arguments)
    return [job for batch in BasicSweeper.split_arguments(parsed, None) for job in batch]


try:
    from hydra.experimental.callback import Callback as _Callback
except ImportError:  # pragma: no cover - hydra is a dependency
    _Callback = object


#: the catalog row of the sweep job running in this process (set by on_job_start)
JOB: dict[str, Any] = {}


class SweepGuard(_Callback):
    """Hydra callback: record the jobs of a multirun when it starts, and each job in the
    catalog as soon as its process takes it, so a worker killed at any moment leaves a row
    that reads as ``died`` (see the module doc)."""

    def on_job_start(self, config, **kwargs) -> None:
        from hydra.core.hydra_config import HydraConfig

        JOB.clear()
        hc = HydraConfig.get()
        if hc.mode.name != "MULTIRUN":
            return
        try:
            listed = json.loads((Path(str(hc.sweep.dir)) / JOBS_FILE).read_text())
            run_id = listed["run_ids"][int(hc.job.num)]
            sweep_id = str(listed.get("sweep_id", ""))
        except (OSError, ValueError, KeyError, IndexError):
            return  # not a sweep this guard started: the job records itself when it starts
        _record_job(str(config.get("outputs_root", "outputs")), run_id,
                    list(hc.overrides.task), str(hc.runtime.output_dir),
                    str(hc.runtime.choices.get("experiment") or "default"))
        JOB["run_id"] = run_id
        JOB["sweep_id"] = sweep_id

    def on_multirun_start(self, config, **kwargs) -> None:
        from omegaconf import OmegaConf

        hydra = config.hydra
        sweep_dir = Path(str(hydra.sweep.dir))
        CURRENT.clear()
        CURRENT["sweep_dir"] = sweep_dir
        if "BasicSweeper" not in str(hydra.sweeper.get("_target_", "")):
            return  # another sweeper chooses its jobs itself: no list to compare with
        params = hydra.sweeper.get("params")
        params = OmegaConf.to_container(params, resolve=True) if params is not None else {}
        jobs = job_overrides(list(hydra.overrides.task), params)
        CURRENT["jobs"] = jobs
        sweep_dir.mkdir(parents=True, exist_ok=True)
        from .results import write_text_atomic
        from .run import new_run_id

        run_ids = [new_run_id() for _ in jobs]
        CURRENT["sweep_id"] = "sweep-" + new_run_id()
        write_text_atomic(sweep_dir / JOBS_FILE, json.dumps(
            {"sweep_id": CURRENT["sweep_id"], "jobs": jobs, "run_ids": run_ids}, indent=1) + "\n")
        # every job has its row from now on, held by this process until a worker takes it:
        # a job whose worker dies before it records itself reads as 'died' once the sweep ends
        root = str(config.get("outputs_root", "outputs"))
        experiment = str(hydra.runtime.choices.get("experiment") or "default")
        for num, (job, run_id) in enumerate(zip(jobs, run_ids)):
            _record_job(root, run_id, job, str(sweep_dir / str(num)), experiment)


def _record_job(root: str, run_id: str, overrides: list[str], path: str, experiment: str) -> None:
    from .provenance import now_iso
    from .run_record import RunRecorder

    RunRecorder(root, run_id).start(experiment=experiment, overrides=overrides, path=path,
                                    git_commit="", start_time=now_iso())


def finished_overrides(sweep_dir: Path) -> list[list[str]]:
    """The override lists of the runs under ``sweep_dir`` that wrote their results."""
    from .results import RESULTS_NAME

    done = []
    for results in sorted(Path(sweep_dir).glob(f"*/{RESULTS_NAME}")):
        try:
            import netCDF4

            with netCDF4.Dataset(results) as nc:
                done.append(list(json.loads(nc.getncattr("overrides"))))
        except Exception:  # noqa: BLE001 - a damaged file is a job that did not finish
            continue
    return done


def unfinished_jobs(sweep_dir: Path, jobs: list[list[str]]) -> list[tuple[int, list[str]]]:
    """(job number, overrides) of every job with no results under ``sweep_dir``."""
    done = {tuple(sorted(o)) for o in finished_overrides(sweep_dir)}
    return [(num, job) for num, job in enumerate(jobs) if tuple(sorted(job)) not in done]


def _status(sweep_dir: Path, num: int) -> str:
    error = Path(sweep_dir) / str(num) / "error.txt"
    if error.is_file():
        first = next((line for line in error.read_text().splitlines() if line.strip()), "")
        return f"failed: {first[:160]}"
    if (Path(sweep_dir) / str(num)).is_dir():
        return "died (its process ended before it finished)"
    return "never started"


def summary(sweep_dir: Path | None, jobs: list[list[str]] | None) -> str:
    """The exit message of a sweep that did not finish every job ('' when all did)."""
    if sweep_dir is None:
        return ""
    if jobs is None:
        return (f"sweep {sweep_dir} did not finish every job; see the job folders there and "
                "`pointatlas-runs list --status failed` / `--status died`.")
    missing = unfinished_jobs(Path(sweep_dir), jobs)
    if not missing:
        return ""
    lines = [f"sweep {sweep_dir}: {len(missing)} of {len(jobs)} runs did not finish:"]
    for num, job in missing:
        lines.append(f"  job {num} ({' '.join(job) or 'no overrides'}): {_status(sweep_dir, num)}")
    lines.append("Rerun just those with:")
    for _, job in missing:
        lines.append("  pointatlas " + " ".join(shlex.quote(o) for o in job))
    return "\n".join(lines)


__all__ = ["SweepGuard", "job_overrides", "unfinished_jobs", "summary", "CURRENT", "JOB"]
