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

from .config import CONF_DIR, plugin_config_class, register_configs, valid_keys
from .errors import ConfigError, PluginError, PointatlasError
from .registry import FAMILIES, load_plugin

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
        key, _, value = override.lstrip("+~").partition("=")
        if key in FAMILIES.values() and value and value != "null":
            load_plugin(key, value)  # unknown: lists installed names; broken: says why
        from .config import experiments

        if key == "experiment" and value not in experiments():
            return (f"No experiment named {value!r}. Available: {', '.join(sorted(experiments()))}. "
                    "Fix the name (experiments/ holds the definitions).")
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
            cfg = compose("config", overrides=[o for o in overrides if "." not in o.split("=")[0]],
                          return_hydra_config=True)
            chosen = cfg.hydra.runtime.choices.get(family)
    config = plugin_config_class(family, chosen) if chosen else None
    return valid_keys(config) if config else []


def check_composition(overrides: list[str]) -> None:
    """Compose the run config once; raise ConfigError/PluginError with a clear message."""
    from hydra import compose, initialize_config_dir
    from hydra.errors import HydraException
    from omegaconf.errors import OmegaConfBaseException

    try:
        with initialize_config_dir(config_dir=str(CONF_DIR), version_base=VERSION_BASE):
            compose("config", overrides=overrides)
    except (HydraException, OmegaConfBaseException, ValueError) as exc:
        raise ConfigError(explain(exc, overrides)) from exc


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
        experiment=choices.get("experiment") or "default",
        config_yaml=OmegaConf.to_yaml(cfg, resolve=True),
    )


def _record_start_failure(overrides: list[str], message: str) -> None:
    """A run that could not even start is still recorded in the catalog (status failed)."""
    from .catalog import Catalog, catalog_path
    from .provenance import git_commit, now_iso
    from .run import new_run_id

    root = next((o.split("=", 1)[1] for o in overrides if o.startswith("outputs_root=")), "outputs")
    experiment = next((o.split("=", 1)[1] for o in overrides if o.startswith("experiment=")), "default")
    now = now_iso()
    try:
        Catalog(catalog_path(root)).record_failure(
            run_id=new_run_id(), experiment=experiment, overrides=overrides, path=None,
            git_commit=git_commit(), start_time=now, end_time=now, error=message)
    except Exception as exc:  # noqa: BLE001 - the config error is what the user must see
        log.warning("could not record the failed run in the catalog: %s", exc)


def main(argv: list[str] | None = None) -> None:
    """Console entry point of ``pointatlas``."""
    import hydra

    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] in ("--help", "-h"):
        from .cli_help import help_text

        print(help_text())
        return
    overrides, multirun, info = split_argv(argv)
    try:
        register_configs()
        if not info:
            check_composition([o for o in overrides if not o.startswith("hydra")] if not multirun
                              else [o for o in overrides if "," not in o and not o.startswith("hydra")
                                    and "(" not in o])
    except PointatlasError as exc:
        print(f"pointatlas: error: {exc}", file=sys.stderr)
        _record_start_failure(overrides, str(exc))
        sys.exit(2)
    sys.argv = [sys.argv[0], *argv]
    app = hydra.main(config_path=str(CONF_DIR), config_name="config", version_base=VERSION_BASE)(_task_safe)
    app()


def _task_safe(cfg) -> None:
    try:
        _task(cfg)
    except PointatlasError as exc:
        from hydra.core.hydra_config import HydraConfig

        if HydraConfig.get().mode.name == "RUN":
            print(f"pointatlas: error: {exc}", file=sys.stderr)
            sys.exit(1)
        raise


__all__ = ["main", "PluginError"]
