"""``pointatlas``: the Hydra application that runs one experiment (or sweeps many).

``pointatlas`` with no arguments runs the default experiment; ``pointatlas
experiment=<name> key=value ...`` runs any experiment; ``--multirun`` sweeps. Before any
work the command line is composed once so that a misspelt key, an unknown plugin or a
wrong type fails at start-up with the valid choices listed.
"""
from __future__ import annotations

import logging
import re
import sys
from pathlib import Path

from .config import CONF_DIR, USER_CONFIG_DIRS, plugin_config_class, register_configs, valid_keys
from .errors import ConfigError, PluginError, PointatlasError
from .registry import FAMILIES, load_plugin
from .user_configs import searchpath_override, user_config_dirs

log = logging.getLogger("pointatlas")
VERSION_BASE = "1.3"
_INFO_FLAGS = {"--help", "-h", "--hydra-help", "--info", "-i", "--cfg", "-c", "--shell-completion",
               "-sc", "--version"}
_VALUE_FLAGS = {"--config-path", "-cp", "--config-name", "-cn", "--config-dir", "-cd",
                "--experimental-rerun", "--package", "-p", "--info", "-i", "--cfg", "-c"}


def split_argv(argv: list[str]) -> tuple[list[str], bool, bool]:
    """(overrides, multirun, informational) from a Hydra command line."""
    overrides, multirun, info = [], False, False
    skip = False
    for arg in argv:
        if skip:
            skip = False
            continue
        if arg in ("--multirun", "-m"):
            multirun = True
        elif arg in _INFO_FLAGS or arg.split("=")[0] in _INFO_FLAGS:
            info = True
            skip = arg in _VALUE_FLAGS and arg in ("--cfg", "-c", "--info", "-i")
        elif arg in _VALUE_FLAGS:
            skip = True
        elif not arg.startswith("-"):
            overrides.append(arg)
    return overrides, multirun, info


def explain(exc: Exception, overrides: list[str]) -> str:
    """Turn a Hydra composition error into one message naming the problem and the fix."""
    text = str(exc)
    for override in overrides:
        if override.startswith("~"):
            continue  # a deletion ('~experiment') names nothing to look up
        key, _, value = override.lstrip("+").partition("=")
        if key in FAMILIES.values() and value and value != "null":
            load_plugin(key, value)  # unknown: lists installed names; broken: says why
        from .config import experiments

        if key == "experiment" and value not in experiments():
            return (f"No experiment named {value!r}. Available: {', '.join(sorted(experiments()))}. "
                    "Fix the name, or add your own as DIR/experiment/<name>.yaml with --config-dir DIR.")
    missing = re.search(r"Could not find '(\w+)/([\w.-]+)'", text)
    if missing and missing.group(1) in FAMILIES.values():
        load_plugin(missing.group(1), missing.group(2))  # raises PluginError naming the cause
    unknown = re.search(r"Could not override '([\w.]+)'", text)
    if unknown:
        key = unknown.group(1)
        family = key.split(".")[0] if "." in key else ""
        valid = _valid_keys_for(family, overrides)
        where = f"of {family} " if family else ""
        hint = f" Valid keys {where}are: {', '.join(valid)}." if valid else ""
        return f"Unknown config key {key!r}.{hint} Fix the spelling of the override."
    if "ConfigKeyError raised while composing" in text:
        where = re.search(r"In '([^']+)'", text)
        return (f"{text.strip().splitlines()[0]} {text.strip().splitlines()[1].strip()}: "
                f"{where.group(1) if where else 'the experiment'} sets a key that the plugin chosen "
                "on the command line does not have. Pick an experiment made for that plugin, or add "
                "~experiment (drop the default experiment) to start from the bare defaults.")
    cause = exc.__cause__
    while cause is not None and cause.__cause__ is not None and str(cause) == text:
        cause = cause.__cause__
    if cause is not None and "Error merging override" in text:
        detail = str(cause).splitlines()[0]
        return f"{text.strip()}: {detail}. Give a value of the type the key expects."
    return f"{text.strip()}\nSee the valid choices with `pointatlas --help`."


def _valid_keys_for(family: str, overrides: list[str]) -> list[str]:
    if family not in FAMILIES.values():
        from .config import RunConfig

        return valid_keys(RunConfig)
    chosen = next((o.split("=", 1)[1] for o in overrides if o.startswith(f"{family}=")), None)
    if chosen is None:
        from hydra import compose, initialize_config_dir

        with initialize_config_dir(config_dir=str(CONF_DIR), version_base=VERSION_BASE):
            cfg = compose("config", overrides=[o for o in overrides if "." not in o.split("=")[0]]
                          + searchpath_override(USER_CONFIG_DIRS), return_hydra_config=True)
            chosen = cfg.hydra.runtime.choices.get(family)
    config = plugin_config_class(family, chosen) if chosen else None
    return valid_keys(config) if config else []


def _compose(overrides: list[str]):
    from hydra import compose, initialize_config_dir
    from hydra.errors import HydraException
    from omegaconf import OmegaConf, open_dict
    from omegaconf.errors import OmegaConfBaseException

    try:
        with initialize_config_dir(config_dir=str(CONF_DIR), version_base=VERSION_BASE):
            cfg = compose("config", overrides=overrides + searchpath_override(USER_CONFIG_DIRS),
                          return_hydra_config=True)
            choices = {k: v for k, v in cfg.hydra.runtime.choices.items()
                       if not k.startswith("hydra")}
            sweeper = OmegaConf.to_container(cfg.hydra.sweeper, resolve=False)
            sweeper["mode"] = str(cfg.hydra.mode)
            with open_dict(cfg):
                del cfg["hydra"]
            return OmegaConf.to_container(cfg, resolve=True), choices, sweeper
    except (HydraException, OmegaConfBaseException, ValueError) as exc:
        raise ConfigError(explain(exc, overrides)) from exc


def check_composition(overrides: list[str], multirun: bool = False) -> bool:
    """Compose the run config (every job's, for a sweep) and check it
    (:func:`pointatlas.config_check.check_run_config`); raise ConfigError/PluginError with a
    clear message naming the job. Returns whether the command is a sweep (``-m``, or a config
    such as ``sweep=n_points`` that sets ``hydra.mode: MULTIRUN``)."""
    from .config_check import check_run_config

    task = [o for o in overrides if not o.startswith("hydra")]
    first = task if not multirun else [o for o in task if "," not in o and "(" not in o]
    config, choices, sweeper = _compose(first)
    jobs = [task]
    multirun = multirun or sweeper.get("mode") == "MULTIRUN"
    if multirun:
        from .sweep_guard import job_overrides

        try:
            jobs = job_overrides(task, (sweeper or {}).get("params"))
        except Exception:  # noqa: BLE001 - a sweep syntax Hydra itself will explain
            jobs = []
    for job in jobs:
        if job != first:  # a single run's config is the one composed above
            config, choices, _ = _compose(job)
        try:
            check_run_config(config, choices)
        except ConfigError as exc:
            if len(jobs) > 1:
                raise ConfigError(f"sweep job {' '.join(job)}: {exc}") from None
            raise
    return multirun


def _task(cfg) -> None:
    from hydra.core.hydra_config import HydraConfig
    from omegaconf import OmegaConf

    from .run import run_study

    hc = HydraConfig.get()
    choices = {k: v for k, v in hc.runtime.choices.items() if not k.startswith("hydra")}
    run_study(
        config=OmegaConf.to_container(cfg, resolve=True),
        choices=choices,
        overrides=list(hc.overrides.task),
        run_dir=hc.runtime.output_dir,
        experiment=choices.get("experiment") or "none",
        config_yaml=OmegaConf.to_yaml(cfg, resolve=True),
        run_id=_EARLY.get("run_id") if hc.mode.name == "RUN" else _job_run_id(),
        sweep_id=None if hc.mode.name == "RUN" else _job_sweep_id(),
    )


def chosen_plugins(overrides: list[str]) -> dict[str, str]:
    """family -> plugin chosen on the command line (``source=file``), sweeps excluded."""
    out = {}
    for override in overrides:
        key, sep, value = override.partition("=")
        if sep and key in FAMILIES.values() and value and "," not in value and value != "null":
            out[key] = value
    return out


def _log_dropped_experiment_settings(overrides: list[str], chosen: dict[str, str]) -> None:
    """Say which of the experiment's settings do not apply to a plugin chosen instead."""
    from omegaconf import OmegaConf

    from .config import experiment_settings_for, experiments

    name = next((o.split("=", 1)[1] for o in overrides if o.startswith("experiment=")),
                None if "~experiment" in overrides else _default_experiment())
    path = experiments().get(name or "")
    if path is None or not chosen:
        return
    node = OmegaConf.load(path)
    for family, plugin in chosen.items():
        block = node.get(family)
        if block is None or not OmegaConf.is_dict(block):
            continue
        _, dropped = experiment_settings_for(family, plugin,
                                             OmegaConf.to_container(block, resolve=False))
        given = {o.split("=", 1)[0].lstrip("+") for o in overrides}
        dropped = {k: v for k, v in dropped.items() if f"{family}.{k}" not in given}
        if dropped:
            shown = ", ".join(f"{family}.{k}={v}" for k, v in dropped.items())
            print(f"pointatlas: experiment {name} sets {shown} for its own {family}; not applied "
                  f"to {family}={plugin} (set them on the command line to apply them).",
                  file=sys.stderr)


def _default_experiment() -> str | None:
    """The experiment conf/config.yaml selects when the command line names none."""
    from omegaconf import OmegaConf

    for entry in OmegaConf.load(CONF_DIR / "config.yaml").get("defaults", []):
        if OmegaConf.is_dict(entry) and "experiment" in entry:
            return entry["experiment"]
    return None


def _job_run_id() -> str | None:
    from .sweep_guard import JOB

    return JOB.get("run_id")


def _job_sweep_id() -> str | None:
    from .sweep_guard import JOB

    return JOB.get("sweep_id") or None


#: the run recorded by :func:`main` before any heavy import (single runs only)
_EARLY: dict = {}


def _record_early(overrides: list[str]) -> None:
    """Record a single run in the catalog with its process before anything heavy happens, so a
    run killed during start-up still has a row (it reads as 'died')."""
    from .provenance import now_iso
    from .run import new_run_id
    from .run_record import RunRecorder

    root = next((o.split("=", 1)[1] for o in overrides if o.startswith("outputs_root=")),
                "outputs")
    experiment = next((o.split("=", 1)[1] for o in overrides if o.startswith("experiment=")),
                      None)
    if experiment is None:
        dropped = any(o.startswith("~experiment") for o in overrides)
        experiment = "none" if dropped else (_default_experiment() or "none")
    if Path(root).exists() and not Path(root).is_dir():
        return  # refused by the start-up check, with the fix
    record = RunRecorder(root, new_run_id())
    record.start(experiment=experiment, overrides=list(overrides), path=None, git_commit="",
                 start_time=now_iso())
    _EARLY.update(run_id=record.run_id, record=record)


def main(argv: list[str] | None = None) -> None:
    """Console entry point of ``pointatlas``."""
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] in ("--help", "-h"):
        from .cli_help import help_text

        print(help_text())
        return
    overrides, multirun, info = split_argv(argv)
    _EARLY.clear()
    if not (info or multirun):
        _record_early(overrides)
    chosen = chosen_plugins(overrides)
    try:
        USER_CONFIG_DIRS[:] = user_config_dirs(argv)
        register_configs(chosen)
        _log_dropped_experiment_settings(overrides, chosen)
        if not info and check_composition(overrides, multirun) and not multirun:
            multirun = True  # a config that sets hydra.mode: MULTIRUN (sweep=...)
            if "record" in _EARLY:
                _EARLY.pop("record").forget()
    except PointatlasError as exc:
        print(f"pointatlas: error: {exc}", file=sys.stderr)
        if "record" not in _EARLY:
            _record_early(overrides)
        if "record" in _EARLY:
            _EARLY["record"].rejected(error=str(exc))
        sys.exit(2)
    import hydra

    sys.argv = [sys.argv[0], *argv]
    app = hydra.main(config_path=str(CONF_DIR), config_name="config", version_base=VERSION_BASE)(_task_safe)
    if not multirun:
        app()
        return
    from . import sweep_guard

    sweep_guard.CURRENT.clear()
    code = 0
    try:
        app()
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    message = sweep_guard.summary(sweep_guard.CURRENT.get("sweep_dir"),
                                  sweep_guard.CURRENT.get("jobs"))
    if message:
        print(f"pointatlas: error: {message}", file=sys.stderr)
        sys.exit(1)
    if code:
        sys.exit(code)
    if sweep_guard.CURRENT.get("sweep_dir") is not None:
        from .sweep import write_sweep

        try:
            path = write_sweep(sweep_guard.CURRENT["sweep_dir"],
                               sweep_guard.CURRENT.get("sweep_id"))
        except Exception as exc:  # noqa: BLE001 - the jobs are done; sweep.nc is a convenience
            print(f"pointatlas: warning: the sweep's jobs finished but sweep.nc could not be "
                  f"written ({type(exc).__name__}: {exc}); open_sweep reads the jobs instead.",
                  file=sys.stderr)
            path = None
        if path is not None:
            log.info("sweep %s: %s", sweep_guard.CURRENT.get("sweep_id") or "", path)


def _task_safe(cfg) -> None:
    from hydra.core.hydra_config import HydraConfig

    try:
        _task(cfg)
    except PointatlasError as exc:
        if HydraConfig.get().mode.name == "RUN":
            print(f"pointatlas: error: {exc}", file=sys.stderr)
            sys.exit(1)
        _job_failed(exc)
    except Exception as exc:  # noqa: BLE001 - one job of a sweep: the others go on
        if HydraConfig.get().mode.name == "RUN":
            raise
        _job_failed(exc)


def _job_failed(exc: BaseException) -> None:
    """A failed job of a sweep: one line (error.txt in its folder has the details); the sweep
    goes on and its exit message lists the jobs to rerun."""
    from hydra.core.hydra_config import HydraConfig

    hc = HydraConfig.get()
    first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
    print(f"pointatlas: error: job {hc.job.num} ({' '.join(hc.overrides.task)}): {first} "
          f"(details: {Path(hc.runtime.output_dir) / 'error.txt'})", file=sys.stderr)


__all__ = ["main", "PluginError"]
