"""Mirror each run into an MLflow tracking store (``tracking=mlflow``).

With ``tracking=mlflow`` every run, finished or failed, becomes one MLflow run named by its
pointatlas run id, in the MLflow experiment ``tracking_experiment`` (default: the pointatlas
experiment's name), in the store ``tracking_uri`` (default: ``$MLFLOW_TRACKING_URI``, else
``./mlruns``, a local file store). It holds:

- params: the resolved config flattened to dotted keys (``source.n_points``), spelt the way an
  override spells them, the plugin choices (``source=square_plate``) and ``experiment``;
- metrics: the run's scalar metrics (those of the catalog row and of the "completed in" line);
- artifacts: ``results.nc`` and ``report.html`` when present, ``error.txt`` for a failed run;
- status ``FINISHED``, or ``FAILED`` with the message in the tag ``pointatlas.error``.

Each job of a sweep is one MLflow run, child of a parent run named after the sweep folder.
The run pipeline calls :func:`mirror_run` when a run ends; the Hydra callback
:class:`MlflowTracking` (``hydra.callbacks`` in ``conf/config.yaml``) refuses
``tracking=mlflow`` at start-up when mlflow is not installed (one line, exit 2) and holds a
sweep's parent run. mlflow is imported only when ``tracking=mlflow`` is chosen. A store that
cannot be written is a warning: the run itself and its results are not affected.
"""
from __future__ import annotations

import datetime as _dt
import logging
import os
import re
import sys
import time
from pathlib import Path
from typing import Any, Mapping
from urllib.parse import urlparse

from .errors import ConfigError

log = logging.getLogger("pointatlas.tracking")

MISSING_MLFLOW = "tracking=mlflow needs mlflow: pip install 'pointatlas[mlflow]'"
#: the store when neither ``tracking_uri`` nor ``MLFLOW_TRACKING_URI`` names one
DEFAULT_STORE = "mlruns"
#: store schemes that need SQLAlchemy (the full ``mlflow``, not ``mlflow-skinny``)
DATABASE_SCHEMES = ("sqlite", "postgresql", "mysql", "mssql")
#: run-directory files logged as artifacts when present (``error.txt``: failed runs only)
ARTIFACTS = ("results.nc", "report.html")
#: set by :class:`MlflowTracking` for the job running in this process: the store it resolved
#: at start-up and, in a sweep, the parent run
JOB: dict[str, Any] = {}


def enabled(config: Mapping[str, Any]) -> bool:
    return str(config.get("tracking") or "none") == "mlflow"


def load_mlflow():
    """``import mlflow``, or the one-line ConfigError that says how to install it."""
    try:
        import mlflow
    except ImportError:
        raise ConfigError(MISSING_MLFLOW) from None
    return mlflow


def tracking_uri(config: Mapping[str, Any]) -> str:
    """The store of the run: ``tracking_uri``, else ``$MLFLOW_TRACKING_URI``, else
    ``./mlruns``; a plain path becomes an absolute ``file://`` URI."""
    uri = str(config.get("tracking_uri") or "") or os.environ.get("MLFLOW_TRACKING_URI", "")
    uri = uri or DEFAULT_STORE
    if not urlparse(uri).scheme or re.match(r"^[A-Za-z]:[\\/]", uri):  # a path (C:\ too)
        return Path(uri).expanduser().resolve().as_uri()
    return uri


def check_tracking(config: Mapping[str, Any]) -> None:
    """Refuse, before any work, a tracking choice that cannot work: ``tracking=mlflow``
    without mlflow, or a database store without SQLAlchemy (mlflow-skinny)."""
    if not enabled(config):
        return
    load_mlflow()
    uri = tracking_uri(config)
    scheme = urlparse(uri).scheme.split("+")[0]
    if scheme in DATABASE_SCHEMES:
        try:
            import sqlalchemy  # noqa: F401 - the full mlflow has it, mlflow-skinny not
        except ImportError:
            raise ConfigError(
                f"{'tracking_uri' if config.get('tracking_uri') else 'MLFLOW_TRACKING_URI'}="
                f"{uri} is a database store, which needs the full mlflow: "
                "pip install mlflow (or pass tracking_uri=file:./mlruns, a local file store)."
            ) from None


def client(uri: str):
    """An ``MlflowClient`` of ``uri``. A local file store is what the user chose (or the
    default): MLflow 3 asks for ``MLFLOW_ALLOW_FILE_STORE`` to use one, so it is set."""
    load_mlflow()
    from mlflow.tracking import MlflowClient

    if urlparse(uri).scheme in ("", "file"):
        os.environ.setdefault("MLFLOW_ALLOW_FILE_STORE", "true")
    return MlflowClient(tracking_uri=uri)


def experiment_id(mlflow_client, name: str) -> str:
    """The id of the MLflow experiment ``name``, created (or restored) if needed."""
    from mlflow.exceptions import MlflowException

    found = mlflow_client.get_experiment_by_name(name)
    if found is None:
        try:
            return mlflow_client.create_experiment(name)
        except MlflowException:  # another job of the sweep created it meanwhile
            found = mlflow_client.get_experiment_by_name(name)
            if found is None:
                raise
    if found.lifecycle_stage == "deleted":
        mlflow_client.restore_experiment(found.experiment_id)
    return found.experiment_id


def flatten(config: Mapping[str, Any]) -> dict[str, str]:
    """``{"source": {"n_points": 121}}`` -> ``{"source.n_points": "121"}`` (as the catalog
    spells settings, :func:`pointatlas.run_filters.flatten_settings`)."""
    from .run_filters import flatten_settings

    return flatten_settings(dict(config or {}), limit=10**9)  # long values clipped later


def run_params(config: Mapping[str, Any], choices: Mapping[str, Any],
               experiment: str) -> dict[str, str]:
    """The MLflow params of a run: flattened config, plugin choices, experiment name."""
    params = flatten(config)
    params.update({str(k): str(v) for k, v in (choices or {}).items()
                   if v and not str(k).startswith("hydra")})
    params["experiment"] = experiment
    return params


def _key(name: str) -> str:
    """An MLflow-valid key (letters, digits, ``_ - . :`` and spaces; 250 characters)."""
    return re.sub(r"[^\w.\- :]", "_", name)[:250]


def _limit(text: str, length: int) -> str:
    return text if len(text) <= length else text[: length - 3] + "..."


def _epoch_ms(iso: str | None) -> int:
    try:
        return int(_dt.datetime.fromisoformat(str(iso)).timestamp() * 1000)
    except ValueError:
        return int(time.time() * 1000)


def _log_all(mlflow_client, run_id: str, params: dict[str, str], metrics: dict[str, float]):
    from mlflow.entities import Metric, Param

    try:
        from mlflow.utils.validation import MAX_PARAM_VAL_LENGTH
    except ImportError:  # pragma: no cover - older MLflow
        MAX_PARAM_VAL_LENGTH = 500
    items = [Param(_key(k), _limit(v, MAX_PARAM_VAL_LENGTH)) for k, v in params.items()]
    for i in range(0, len(items), 100):
        mlflow_client.log_batch(run_id, params=items[i:i + 100])
    now = int(time.time() * 1000)
    values = [Metric(_key(k), float(v), now, 0) for k, v in metrics.items()]
    for i in range(0, len(values), 1000):
        mlflow_client.log_batch(run_id, metrics=values[i:i + 1000])


def mirror_run(config: Mapping[str, Any], *, run_id: str, run_dir: str | os.PathLike,
               experiment: str, choices: Mapping[str, Any], overrides: list[str],
               start_time: str | None = None, metrics: Mapping[str, float] | None = None,
               warnings: str = "", error: str | None = None) -> str | None:
    """Record one ended run in MLflow (``FAILED`` when ``error`` is given); return the MLflow
    run id, or None when tracking is off or the store could not be written (a warning)."""
    if not enabled(config):
        return None
    uri = JOB.get("uri") or tracking_uri(config)
    mlflow_run = None
    try:
        mlflow_client = client(uri)
        name = str(config.get("tracking_experiment") or "") or experiment
        tags = {"pointatlas.run_id": run_id, "pointatlas.run_dir": str(Path(run_dir).resolve()),
                "pointatlas.experiment": experiment,
                "pointatlas.overrides": _limit(" ".join(overrides), 5000),
                "pointatlas.status": "failed" if error is not None else (
                    "completed_with_warnings" if warnings else "completed")}
        if warnings:
            tags["pointatlas.warnings"] = _limit(warnings, 5000)
        if error is not None:
            tags["pointatlas.error"] = _limit(error, 5000)
        if JOB.get("parent_run_id"):
            tags["mlflow.parentRunId"] = JOB["parent_run_id"]
        mlflow_run = mlflow_client.create_run(experiment_id(mlflow_client, name),
                                              start_time=_epoch_ms(start_time), tags=tags,
                                              run_name=run_id).info.run_id
        _log_all(mlflow_client, mlflow_run, run_params(config, choices, experiment),
                 dict(metrics or {}) if error is None else {})
        files = ARTIFACTS if error is None else ("error.txt",)
        for file in (Path(run_dir) / f for f in files):
            if file.is_file():
                mlflow_client.log_artifact(mlflow_run, str(file))
        mlflow_client.set_terminated(mlflow_run, "FAILED" if error is not None else "FINISHED")
        log.info("run %s tracked in MLflow: %s (run %s)", run_id, uri, mlflow_run)
        return mlflow_run
    except Exception as exc:  # noqa: BLE001 - the run is done; tracking must not undo it
        _warn(f"run {run_id} was not fully recorded in MLflow at {uri}", exc)
        if mlflow_run is not None:
            try:
                mlflow_client.set_terminated(mlflow_run, "FAILED")
            except Exception:  # noqa: BLE001
                pass
        return None


def _warn(what: str, exc: BaseException) -> None:
    first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
    log.warning("%s: %s: %s", what, type(exc).__name__, first[:300])


try:
    from hydra.experimental.callback import Callback as _Callback
except ImportError:  # pragma: no cover - hydra is a dependency
    _Callback = object


def refuse(message: str) -> None:
    """Stop with one line, exit 2. The command line refuses a tracking choice that cannot work
    before Hydra starts (:func:`pointatlas.config_check.check_run_config`); this is for
    callers that start Hydra themselves."""
    print(f"pointatlas: error: {message}", file=sys.stderr)
    sys.exit(2)


class MlflowTracking(_Callback):
    """Hydra callback of ``tracking=mlflow`` (see the module doc): the start-up check, the
    store resolved before any ``chdir``, and a sweep's parent run."""

    def __init__(self) -> None:
        self.uri: str | None = None
        self.parent_run_id: str | None = None

    def _start(self, config) -> bool:
        try:
            check_tracking(config)
        except ConfigError as exc:
            refuse(str(exc))
        if not enabled(config):
            return False
        self.uri = tracking_uri(config)
        return True

    def on_run_start(self, config, **kwargs) -> None:
        self._start(config)

    def on_multirun_start(self, config, **kwargs) -> None:
        self.parent_run_id = None
        if not self._start(config):
            return
        sweep_dir = Path(str(config.hydra.sweep.dir))
        experiment = str(config.hydra.runtime.choices.get("experiment") or "none")
        name = str(config.get("tracking_experiment") or "") or experiment
        try:
            mlflow_client = client(self.uri)
            tags = {"pointatlas.sweep_dir": str(sweep_dir.resolve()),
                    "pointatlas.experiment": experiment,
                    "pointatlas.overrides": _limit(" ".join(config.hydra.overrides.task), 5000)}
            self.parent_run_id = mlflow_client.create_run(
                experiment_id(mlflow_client, name), tags=tags,
                run_name=f"sweep {sweep_dir.parent.name}/{sweep_dir.name}").info.run_id
        except Exception as exc:  # noqa: BLE001 - the jobs are tracked without a parent
            _warn(f"the sweep's parent run could not be created in MLflow at {self.uri}", exc)

    def on_job_start(self, config, **kwargs) -> None:
        JOB.clear()
        if self.uri:
            JOB["uri"] = self.uri
        if self.parent_run_id:
            JOB["parent_run_id"] = self.parent_run_id

    def on_multirun_end(self, config, **kwargs) -> None:
        if not self.parent_run_id:
            return
        try:
            mlflow_client = client(self.uri)
            parent = mlflow_client.get_run(self.parent_run_id)
            failed = mlflow_client.search_runs(
                [parent.info.experiment_id], max_results=1,
                filter_string=f"tags.mlflow.parentRunId = '{self.parent_run_id}' "
                              "and attributes.status = 'FAILED'")
            mlflow_client.set_terminated(self.parent_run_id, "FAILED" if failed else "FINISHED")
        except Exception as exc:  # noqa: BLE001
            _warn(f"the sweep's parent run {self.parent_run_id} could not be ended in MLflow", exc)


__all__ = ["MlflowTracking", "mirror_run", "check_tracking", "tracking_uri", "run_params",
           "flatten", "MISSING_MLFLOW"]
