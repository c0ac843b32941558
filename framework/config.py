"""Config schemas: every plugin's ``Config`` dataclass becomes a Hydra structured config.

``register_configs()`` stores, for each installed plugin, its ``Config`` under
``group=<family>, name=<plugin name>`` (so ``embedder=isomap embedder.n_neighbors=12`` is
checked against the dataclass at start-up), the run schema ``base_config``, and the
experiment definitions of ``experiments/`` under the group ``experiment``.
"""
from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .registry import FAMILIES, describe, discover, load_all

#: where the project's own config groups and experiment definitions live (editable install)
PROJECT_ROOT = Path(__file__).resolve().parent.parent
CONF_DIR = PROJECT_ROOT / "conf"


def experiments_dirs() -> list[Path]:
    """Folders whose ``*.yaml`` files are experiment definitions (``POINTATLAS_EXPERIMENTS``
    adds more, separated by ``os.pathsep``)."""
    extra = [Path(p) for p in os.environ.get("POINTATLAS_EXPERIMENTS", "").split(os.pathsep) if p]
    return [PROJECT_ROOT / "experiments", *extra]


@dataclass
class RunConfig:
    """Top-level keys of every run (the plugin groups are filled by the defaults list)."""

    source: Any = None
    embedder: Any = None
    approximant: Any = None
    physics: Any = None
    study: Any = None
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


def valid_keys(config_class: type) -> list[str]:
    return [f.name for f in dataclasses.fields(config_class)]


def plugin_config_class(family: str, name: str) -> type | None:
    """The ``Config`` dataclass of an installed plugin, or None if it cannot be loaded."""
    from .registry import group_name

    cls = load_all(group_name(family)).get(name)
    return getattr(cls, "Config", None) if cls else None


def register_configs() -> None:
    """Fill Hydra's ConfigStore with the run schema, plugin configs and experiments."""
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
    for folder in experiments_dirs():
        for path in sorted(folder.glob("*.yaml")):
            cs.store(group="experiment", name=path.stem, node=OmegaConf.load(path), package="_global_")


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
