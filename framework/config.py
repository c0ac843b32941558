"""Config schemas: every plugin's ``Config`` dataclass becomes a Hydra structured config.

``register_configs()`` stores, for each installed plugin, its ``Config`` under
``group=<family>, name=<plugin name>`` (so ``embedder=isomap embedder.n_neighbors=12`` is
checked against the dataclass at start-up), the run schema ``base_config``, and the
experiment definitions of ``experiments/`` under the group ``experiment``.
"""
from __future__ import annotations

import dataclasses
import enum
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .registry import FAMILIES, describe, discover, load_all

_PACKAGE = Path(__file__).resolve().parent


def _shipped(name: str) -> Path:
    """``pointatlas/<name>`` of an installed wheel, else ``<checkout>/<name>`` (editable)."""
    inside = _PACKAGE / name
    return inside if inside.is_dir() else _PACKAGE.parent / name


#: the project's own config groups (Hydra's primary config directory)
CONF_DIR = _shipped("conf")
#: the project's own experiment definitions
EXPERIMENTS_DIR = _shipped("experiments")
#: config directories the user added (``--config-dir``, ``hydra.searchpath``), set by the CLI;
#: their ``experiment/`` folders hold the user's experiments
USER_CONFIG_DIRS: list[Path] = []


def experiments_dirs() -> list[Path]:
    """Folders whose ``*.yaml`` files are experiment definitions: the shipped ones, the
    ``experiment/`` folder of each user config directory (``--config-dir``,
    ``hydra.searchpath``), then ``POINTATLAS_EXPERIMENTS`` (folders separated by
    ``os.pathsep``, for Python callers that compose without the CLI). A later folder's
    experiment replaces a shipped one of the same name."""
    extra = [Path(p) for p in os.environ.get("POINTATLAS_EXPERIMENTS", "").split(os.pathsep) if p]
    return [EXPERIMENTS_DIR, *(d / "experiment" for d in USER_CONFIG_DIRS), *extra]


class Tracking(enum.StrEnum):
    """Values of the top-level key ``tracking`` (a misspelt one is refused at start-up)."""

    none = "none"
    mlflow = "mlflow"


class UnitsSystem(enum.StrEnum):
    """Values of the top-level key ``units_system`` (:mod:`pointatlas.units`)."""

    SI = "SI"
    mm_N_s = "mm_N_s"
    nondimensional = "nondimensional"


@dataclass
class RunConfig:
    """Top-level keys of every run (the plugin groups are filled by the defaults list)."""

    source: Any = None
    embedder: Any = None
    approximant: Any = None
    physics: Any = None
    study: Any = None
    #: the atlas settings (``atlas.gamma_lme=...``; the ``atlas`` plugin family)
    atlas: Any = None
    #: where the per-patch work runs: local (default), dask, dask_slurm (pointatlas.executor)
    executor: Any = None
    #: seeds every random choice of the run (numpy, random, scikit-learn, generators)
    seed: int = 0
    #: only warnings and errors in the log (no progress lines)
    quiet: bool = False
    #: root of run directories and of the run catalog (catalog.sqlite)
    outputs_root: str = "outputs"
    #: human title of the run, stored as the results' ``title`` attr
    title: str = ""
    #: experiment-specific settings (reference values, lists of embedders...)
    extra: dict = dataclasses.field(default_factory=dict)
    #: units of the results of problems posed in consistent units (a shell's lengths, forces):
    #: SI (m, N, J), mm_N_s (mm, N, mJ) or nondimensional (pointatlas.units)
    units_system: UnitsSystem = UnitsSystem.SI
    #: mirror the run into an experiment tracker: none, or mlflow (pointatlas.mlflow_tracking)
    tracking: Tracking = Tracking.none
    #: the MLflow store ('' = $MLFLOW_TRACKING_URI, else ./mlruns); e.g. file:/abs/mlruns
    tracking_uri: str = ""
    #: the MLflow experiment ('' = the pointatlas experiment's name)
    tracking_experiment: str = ""


def valid_keys(config_class: type) -> list[str]:
    return [f.name for f in dataclasses.fields(config_class)]


def plugin_config_class(family: str, name: str) -> type | None:
    """The ``Config`` dataclass of an installed plugin, or None if it cannot be loaded."""
    from .registry import group_name

    cls = load_all(group_name(family)).get(name)
    return getattr(cls, "Config", None) if cls else None


#: dataclass-field metadata of a plugin setting that experiments do not set for it: an
#: experiment's value (a generator's resolution, ``source.n_points``) is not applied when the
#: plugin was chosen on the command line instead of the experiment's own (a user's file)
NOT_FROM_EXPERIMENTS = "not_from_experiments"


def experiment_settings_for(family: str, name: str, block: dict) -> tuple[dict, dict]:
    """(kept, dropped): the part of an experiment's ``family`` settings that applies to the
    plugin ``name`` chosen on the command line: the keys its Config has, less those marked
    :data:`NOT_FROM_EXPERIMENTS`."""
    config = plugin_config_class(family, name)
    if config is None:
        return dict(block), {}
    valid = {f.name for f in dataclasses.fields(config)
             if not f.metadata.get(NOT_FROM_EXPERIMENTS)}
    kept = {k: v for k, v in block.items() if k in valid}
    return kept, {k: v for k, v in block.items() if k not in valid}


def register_configs(chosen: dict[str, str] | None = None) -> None:
    """Fill Hydra's ConfigStore with the run schema, plugin configs and experiments.

    ``chosen``: family -> plugin chosen on the command line (``source=file``). An experiment
    that selects another plugin of that family keeps only the settings that apply to the chosen
    one (:func:`experiment_settings_for`): ``experiment=sphere_willmore_random source=file``
    does not pass the sphere's ``sampling`` to the file, nor its ``n_points`` to cut the file.
    """
    from hydra.core.config_store import ConfigStore
    from omegaconf import OmegaConf

    cs = ConfigStore.instance()
    cs.store(name="base_config", node=RunConfig)
    for group, family in FAMILIES.items():
        for name, cls in load_all(group).items():
            config = getattr(cls, "Config", None)
            if config is None or not dataclasses.is_dataclass(config):
                import warnings

                warnings.warn(
                    f"{family} plugin {name!r} has no Config dataclass; it cannot be selected "
                    "from configs.", RuntimeWarning, stacklevel=2,
                )
                continue
            cs.store(group=family, name=name, node=config, provider=discover(group)[name].distribution)
    # a user's config folders are Hydra's to read (a stored config of the same name would be
    # taken as its schema): store only the others, less any name a user folder redefines
    users = {p.stem for d in USER_CONFIG_DIRS for p in (d / "experiment").glob("*.yaml")}
    for folder in experiments_dirs():
        if folder.parent in USER_CONFIG_DIRS and folder.name == "experiment":
            continue
        for path in sorted(folder.glob("*.yaml")):
            if path.stem in users:
                continue
            node = OmegaConf.load(path)
            for family, name in (chosen or {}).items():
                block = node.get(family)
                if block is not None and OmegaConf.is_dict(block):
                    kept, _ = experiment_settings_for(
                        family, name, OmegaConf.to_container(block, resolve=False))
                    node[family] = kept
            cs.store(group="experiment", name=path.stem, node=node, package="_global_")


def experiment_usage(path: Path) -> str:
    """The one-line usage comment of an experiment file."""
    for line in path.read_text().splitlines():
        if line.lower().startswith("# usage:"):
            return line[2:].strip()
    return ""


def experiments() -> dict[str, Path]:
    """Experiment definitions by name."""
    out = {}
    for folder in experiments_dirs():
        for path in sorted(folder.glob("*.yaml")):
            out[path.stem] = path
    return out


__all__ = ["RunConfig", "register_configs", "valid_keys", "plugin_config_class", "describe",
           "experiments", "experiment_usage", "CONF_DIR"]
