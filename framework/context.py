"""What a study sees of its run: resolved config, seeded RNGs, plugins, output dir, logger."""
from __future__ import annotations

import dataclasses
import logging
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .errors import ConfigError
from .jit_time import StageTimer
from .progress import Heartbeat, Progress
from .registry import load_plugin


def plugin_kwargs(node: Any) -> dict:
    """A plugin's config node (DictConfig, dataclass or dict) as plain keyword arguments."""
    if node is None:
        return {}
    if dataclasses.is_dataclass(node) and not isinstance(node, type):
        return dataclasses.asdict(node)
    try:
        from omegaconf import DictConfig, OmegaConf

        if isinstance(node, DictConfig):
            return OmegaConf.to_container(node, resolve=True)  # type: ignore[return-value]
    except ImportError:  # pragma: no cover
        pass
    return dict(node)


@dataclass
class RunContext:
    """The run as a study sees it.

    Attributes
    ----------
    config : resolved run config (nested dicts), keys as in ``conf/``
    choices : family -> selected plugin name (``{"embedder": "isomap", ...}``)
    seed : the run's ``seed``; every RNG derives from it
    run_dir : where the run writes its files
    """

    config: dict
    choices: dict[str, str]
    seed: int = 0
    run_dir: Path = Path(".")
    log: logging.Logger = field(default_factory=lambda: logging.getLogger("pointatlas.run"))
    timings: dict[str, float] = field(default_factory=dict)
    #: what the source said of the points it gave (PointCloud.info), for the results
    source_info: dict = field(default_factory=dict)

    def rng(self, stream: str = "") -> np.random.Generator:
        """A generator seeded by the run seed and a stream name (independent streams)."""
        key = zlib.crc32(stream.encode())
        return np.random.default_rng(np.random.SeedSequence([self.seed, key]))

    def plugin_name(self, family: str) -> str:
        name = self.choices.get(family)
        if not name:
            raise ConfigError(
                f"this run selects no {family} plugin but its study needs one. Add "
                f"`{family}=<name>` (list them with `pointatlas-runs plugins` or "
                f"`python -c 'import pointatlas; print(pointatlas.plugins())'`)."
            )
        return name

    def plugin(self, family: str, **overrides: Any):
        """The selected plugin of ``family`` built from its config (plus ``overrides``)."""
        name = self.plugin_name(family)
        kwargs = {**plugin_kwargs(self.config.get(family)), **overrides}
        plugin = self.make(family, name, **kwargs)
        return _RecordedSource(plugin, self.source_info) if family == "source" else plugin

    def make(self, family: str, name: str, /, **kwargs: Any):
        """Build any installed plugin by name; config defaults fill missing keywords."""
        cls = load_plugin(family, name)
        config = getattr(cls, "Config", None)
        if config is not None:
            valid = {f.name for f in dataclasses.fields(config)}
            bad = sorted(set(kwargs) - valid)
            if bad:
                raise ConfigError(
                    f"{family} plugin {name!r} has no setting(s) {bad}. Valid keys: "
                    f"{', '.join(sorted(valid))}."
                )
            kwargs = {**dataclasses.asdict(config()), **kwargs} if _constructible(config) else kwargs
        return cls(**kwargs)

    def progress(self, iterable=None, *, total: int | None = None, desc: str = "work") -> Progress:
        return Progress(iterable, total=total, desc=desc, logger=self.log)

    def timed(self, label: str):
        """Context manager adding the wall time of a block, less numba's compilation in it
        (:mod:`pointatlas.jit_time`), to ``timings[label]`` (s); a block that runs longer
        than 10 s logs that it is still running every 10 s."""
        return _Timer(self.timings, label, self.log)


class _RecordedSource:
    """The run's source, whose ``load`` also records the cloud's ``info`` (how many points the
    source holds and how many it used) for the results; everything else passes through."""

    def __init__(self, source, store: dict):
        self._source, self._store = source, store

    def load(self, *args, **kwargs):
        cloud = self._source.load(*args, **kwargs)
        self._store.update(getattr(cloud, "info", {}) or {})
        return cloud

    def __getattr__(self, name: str):
        return getattr(self._source, name)


def _constructible(config: type) -> bool:
    try:
        config()
    except TypeError:
        return False
    return True


class _Timer(StageTimer):
    """A stage's wall time less numba's compilation, with a heartbeat in long stages."""

    def __init__(self, store: dict, label: str, logger=None):
        super().__init__(store, label)
        self.heartbeat = Heartbeat(label, logger)

    def __enter__(self):
        self.heartbeat.__enter__()
        return super().__enter__()

    def __exit__(self, *exc):
        self.heartbeat.__exit__(*exc)
        return super().__exit__(*exc)
