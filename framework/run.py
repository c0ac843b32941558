"""The run pipeline: seed, build the study's context, run it, write results, catalog it."""
from __future__ import annotations

import json
import logging
import random
import time
import traceback
import uuid
from pathlib import Path

import numpy as np

from .context import RunContext
from .errors import PointatlasError
from .executor import SerialExecutor, using_executor
from .headline import declare_headline
from .jit_time import compile_seconds
from .provenance import command_line, git_commit, hostname, now_iso, source_attr
from .registry import FAMILIES
from .results import (check_variables, metric_names, metric_values, write_results,
                      write_text_atomic)
from .run_files import ERROR_FILE, RESULTS_NAME, RUN_FILE, remove_partial_files
from .liveness import identity
from .mlflow_tracking import mirror_run
from .run_filters import flatten_settings
from .run_record import RunRecorder
from .units import convert_units

log = logging.getLogger("pointatlas.run")
PLUGIN_FAMILIES = tuple(FAMILIES.values())



def new_run_id() -> str:
    return time.strftime("%Y%m%d-%H%M%S-") + uuid.uuid4().hex[:8]


def seed_everything(seed: int) -> None:
    """Seed the global RNGs too, for libraries that use them (the run's own RNGs derive from
    :meth:`RunContext.rng`)."""
    random.seed(seed)
    np.random.seed(seed % 2**32)


def run_study(*, config: dict, choices: dict[str, str], overrides: list[str], run_dir: Path,
              experiment: str = "default", config_yaml: str = "", run_id: str | None = None,
              sweep_id: str | None = None) -> Path:
    """Run the selected study and write ``run_dir/results.nc``; record it in the catalog.

    Parameters
    ----------
    config : resolved run config (plain dicts)
    choices : family -> plugin name selected for the run (``study`` is required)
    overrides : the command-line overrides of this run (for the catalog and sweeps)
    run_id : the id under which the command line already recorded this run (a new one if None)
    sweep_id : the sweep this run is a job of (a ``sweep`` setting in the catalog, an attr)

    A study that sets ``ds.attrs["warnings"]`` (results it cannot fully vouch for, e.g. an
    atlas with patches that failed the chart test, allowed by the user) is recorded as
    ``completed_with_warnings`` with that text.

    Whatever fails after the run is recorded (the study, the results write, the metrics)
    marks the run ``failed`` in the catalog with its message and writes ``error.txt``; a
    catalog that cannot be used is reported once and does not stop the run.
    """
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    remove_partial_files(run_dir)
    seed = int(config.get("seed", 0))
    run_id = run_id or new_run_id()
    record = RunRecorder(config.get("outputs_root", "outputs"), run_id)
    commit, start = git_commit(), now_iso()
    plugins = {f: n for f, n in choices.items() if f in PLUGIN_FAMILIES and n}
    params = {**flatten_settings(config), **plugins, "seed": str(seed),
              **({"sweep": sweep_id} if sweep_id else {})}
    record.start(experiment=experiment, overrides=list(overrides), path=str(run_dir.resolve()),
                 git_commit=commit, start_time=start, params=params)
    record.start_heartbeat()
    write_text_atomic(run_dir / RUN_FILE, json.dumps({
        "run_id": run_id, "experiment": experiment, "overrides": list(overrides),
        "params": params, "git_commit": commit, "start_time": start,
        **identity()}, indent=1) + "\n")
    tracked = dict(run_id=run_id, run_dir=run_dir, experiment=experiment, choices=choices,
                   overrides=list(overrides), start_time=start)
    compile0 = compile_seconds()
    t0 = time.perf_counter()
    if config.get("quiet"):
        logging.getLogger("pointatlas").setLevel(logging.WARNING)
    try:
        ctx = RunContext(config=config, choices=plugins, seed=seed, run_dir=run_dir)
        seed_everything(seed)
        study = ctx.plugin("study")
        log.info("run %s: experiment=%s study=%s in %s", run_id, experiment, plugins["study"], run_dir)
        # executor=dask: the atlas's patches and the assembly run on a Dask cluster
        executor = ctx.plugin("executor") if plugins.get("executor") else SerialExecutor()
        with using_executor(executor):
            if callable(getattr(executor, "start", None)):
                executor.start()  # a cluster that cannot be used stops the run here
            ds = study.run(ctx)
        check_variables(ds)
        wall = time.perf_counter() - t0
        for key, value in sorted(ctx.source_info.items()):
            if isinstance(value, (int, float)) and f"source_{key}" not in ds:
                ds[f"source_{key}"] = ((), value, {"long_name": f"source: {key.replace('_', ' ')}",
                                                   "units": "1"})
        for label, seconds in sorted(ctx.timings.items()):
            ds[f"time_{label}"] = ((), seconds, {
                "long_name": f"wall time of {label} (numba compilation excluded)", "units": "s"})
        ds["time_jit_compile"] = ((), compile_seconds() - compile0, {
            "long_name": "wall time of numba compilation (and cache loads) in the run",
            "units": "s"})
        references = getattr(type(study), "references", {}) or {}
        headline = declare_headline(ds, type(study), config)
        attrs = {
            "Conventions": "CF-1.10",
            "title": config.get("title") or ds.attrs.get("title") or f"pointatlas {experiment}",
            "source": source_attr(plugins),
            "history": f"{start}: {command_line()}",
            "config": config_yaml,
            "overrides": list(overrides),
            "git_commit": commit,
            "seed": seed,
            "hostname": hostname(),
            "wall_time_s": wall,
            "status": "completed_with_warnings" if ds.attrs.get("warnings") else "completed",
            "start_time": start,
            "end_time": now_iso(),
            "run_id": run_id,
            "experiment": experiment,
            "sweep_id": sweep_id or "",
            "study": plugins["study"],
            "plugins": plugins,
            "metrics": metric_names(ds),
            "headline": headline,
            "references": references,
        }
        convert_units(ds, str(config.get("units_system") or "SI"))
        metrics = metric_values(ds)
        path = write_results(ds, run_dir / RESULTS_NAME, attrs)
    except BaseException as exc:
        message = str(exc) if isinstance(exc, PointatlasError) else (
            f"{type(exc).__name__}: {exc}\n{traceback.format_exc()}")
        record.failed(wall_time_s=time.perf_counter() - t0, error=message or type(exc).__name__)
        write_text_atomic(run_dir / ERROR_FILE, (message or type(exc).__name__) + "\n")
        mirror_run(config, **tracked, error=message or type(exc).__name__)  # tracking=mlflow
        raise
    record.completed(wall_time_s=wall, metrics=metrics, warnings=str(ds.attrs.get("warnings") or ""))
    shown = ", ".join(f"{k}={v:.6g}" for k, v in metrics.items() if not k.startswith("time_"))
    log.info("run %s completed in %.2f s: %s", run_id, wall, shown)
    log.info("results: %s", path)
    mirror_run(config, **tracked, metrics=metrics, warnings=str(ds.attrs.get("warnings") or ""))
    root = Path(config.get("outputs_root", "outputs")).resolve()
    log.info("outputs root: %s (catalog %s; `pointatlas-runs list --root %s`)", root,
             root / "catalog.sqlite", root)
    return path


__all__ = ["run_study", "seed_everything", "new_run_id"]
