"""The ``atlas`` config group: the run's atlas settings (``atlas.<key>`` on the command line).

The atlas of a point set (thesis §3: METIS patches, per-patch embeddings, LME charts, a
Shepard partition of unity, Gauss quadrature) is built by the studies and the physics that
need one; what it is built with is one set of :class:`~.settings.AtlasSettings`, chosen by
``atlas=default`` and set with ``atlas.gamma_lme=0.8``, ``atlas.orientation=[0, 0, 1]``...
Until this release the studies held these settings themselves (``study.gamma_lme``): those
spellings still work for one release, with a deprecation message
(:func:`study_atlas_settings`).
"""
from __future__ import annotations

import dataclasses
from typing import ClassVar

from pointatlas.stores_config import stores_config

from .settings import AtlasSettings


@stores_config
class PointSetAtlas:
    """The atlas settings of a run (see the module docstring)."""

    Config = AtlasSettings
    description: ClassVar[str] = (
        "Atlas of a point set: METIS patches, per-patch embeddings, LME charts, Shepard "
        "partition of unity, Gauss quadrature (thesis §3).")

    def settings(self) -> AtlasSettings:
        return AtlasSettings.of(self)

    def check_config(self) -> None:
        self.settings().check()


_WARNED: set[str] = set()


def study_atlas_settings(ctx, study, **preferred) -> AtlasSettings:
    """The atlas settings a study uses: the run's ``atlas.*`` settings; a ``study.<key>`` of
    the old spelling that the run sets (differs from the study's default) still wins, with a
    deprecation message; ``preferred``: the study's own defaults for settings the user left
    at None (``markers_per_patch``: 150 for geometry, 100 for shells).
    """
    if ctx is not None and ctx.choices.get("atlas"):
        base = ctx.plugin("atlas").settings()
    else:
        base = AtlasSettings()
    values = dataclasses.asdict(base)
    config = getattr(type(study), "Config", None)
    atlas_keys = {f.name for f in dataclasses.fields(AtlasSettings)}
    if config is not None:
        defaults = {f.name: (f.default if f.default is not dataclasses.MISSING else
                             f.default_factory())  # type: ignore[misc]
                    for f in dataclasses.fields(config) if f.name in atlas_keys}
        for key, default in defaults.items():
            value = getattr(study, key, default)
            if value != default:
                if key not in _WARNED and ctx is not None:
                    _WARNED.add(key)
                    ctx.log.warning("study.%s is deprecated: write atlas.%s=%r (the study.* "
                                    "spelling of atlas settings goes in the next release)",
                                    key, key, value)
                values[key] = value
    for key, value in preferred.items():
        if values.get(key) is None:
            values[key] = value
    return AtlasSettings(**values)
