"""Plugin discovery through Python entry points.

A plugin family is an entry-point group (``pointatlas.embedders``) and a Hydra config group
(``embedder``); the entry-point name is the config name and the command-line choice
(``embedder=isomap``). Built-in plugins register through the project's own ``pyproject``
exactly as a third party does. Discovery is one cached function with a refresh
(:func:`refresh`), split in small testable steps: read, check duplicates, load.
"""
from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass
from importlib.metadata import EntryPoint, entry_points

from .errors import PluginError

#: entry-point group -> Hydra config group (the name used on the command line).
FAMILIES: dict[str, str] = {
    "pointatlas.sources": "source",
    "pointatlas.embedders": "embedder",
    "pointatlas.approximants": "approximant",
    "pointatlas.physics": "physics",
    "pointatlas.studies": "study",
    "pointatlas.atlases": "atlas",
    "pointatlas.executors": "executor",
}
_ALIASES = {short: group for group, short in FAMILIES.items()}
_ALIASES.update({group.split(".", 1)[1]: group for group in FAMILIES})


def group_name(family: str) -> str:
    """Full entry-point group for ``family`` ('embedder', 'embedders' or 'pointatlas.embedders')."""
    if family in FAMILIES:
        return family
    if family in _ALIASES:
        return _ALIASES[family]
    raise PluginError(
        f"Unknown plugin family {family!r}. Valid families: {', '.join(sorted(FAMILIES.values()))}."
    )


@dataclass(frozen=True)
class PluginInfo:
    """One installed plugin as the registry sees it, before it is imported."""

    name: str
    group: str
    value: str
    distribution: str
    version: str

    @property
    def family(self) -> str:
        return FAMILIES.get(self.group, self.group)


def _info(ep: EntryPoint, group: str) -> PluginInfo:
    dist = getattr(ep, "dist", None)
    return PluginInfo(
        name=ep.name,
        group=group,
        value=ep.value,
        distribution=getattr(dist, "name", None) or "unknown",
        version=getattr(dist, "version", None) or "unknown",
    )


def _dedupe(infos: list[PluginInfo]) -> dict[str, PluginInfo]:
    """Map name -> plugin; two *distributions* claiming one name is an error naming both.

    The same distribution seen twice (an editable install found on two paths) is one plugin.
    """
    out: dict[str, PluginInfo] = {}
    for info in infos:
        seen = out.get(info.name)
        if seen is None:
            out[info.name] = info
        elif (seen.distribution, seen.value) != (info.distribution, info.value):
            raise PluginError(
                f"Two distributions claim the {info.family} plugin {info.name!r} in group "
                f"{info.group!r}: {seen.distribution} {seen.version} ({seen.value}) and "
                f"{info.distribution} {info.version} ({info.value}). Uninstall one of them "
                f"(pip uninstall {info.distribution}) so that runs are reproducible."
            )
    return out


def _read(group: str) -> list[PluginInfo]:
    return [_info(ep, group) for ep in entry_points(group=group)]


@functools.cache
def discover(group: str) -> dict[str, PluginInfo]:
    """Installed plugins of one group, by name (cached; see :func:`refresh`)."""
    return _dedupe(_read(group_name(group)))


def refresh() -> None:
    """Forget what was discovered and loaded (after installing a plugin in-process)."""
    discover.cache_clear()
    _load.cache_clear()


@functools.cache
def _load(group: str, name: str, value: str) -> type:
    return EntryPoint(name=name, value=value, group=group).load()


def load_plugin(group: str, name: str) -> type:
    """Return the plugin class registered as ``name`` in ``group``.

    Parameters
    ----------
    group : 'embedders', 'embedder' or 'pointatlas.embedders' (any family spelling).
    name : the entry-point name, e.g. ``'isomap'``.
    """
    group = group_name(group)
    installed = discover(group)
    if name not in installed:
        usable = sorted(installed)
        raise PluginError(
            f"No {FAMILIES[group]} plugin named {name!r}. Installed: "
            f"{', '.join(usable) if usable else '(none)'}. Fix the spelling, or install the "
            f"package that provides it (it must declare an entry point in group {group!r})."
        )
    info = installed[name]
    try:
        return _load(group, name, info.value)
    except Exception as exc:  # noqa: BLE001 - report any import failure by name
        raise PluginError(
            f"The {FAMILIES[group]} plugin {name!r} ({info.value}, from {info.distribution} "
            f"{info.version}) failed to import: {type(exc).__name__}: {exc}. Installed "
            f"{FAMILIES[group]} plugins: {', '.join(sorted(installed))}. Reinstall "
            f"{info.distribution} or fix its dependencies."
        ) from exc


def load_all(group: str) -> dict[str, type]:
    """Every importable plugin of ``group``; a broken one warns and is skipped."""
    out = {}
    for name in discover(group):
        try:
            out[name] = load_plugin(group, name)
        except PluginError as exc:
            warnings.warn(str(exc), RuntimeWarning, stacklevel=2)
    return out


def describe(cls: type) -> str:
    """One-line description of a plugin: its ``description`` attribute or docstring's first line."""
    text = getattr(cls, "description", None) or (cls.__doc__ or "").strip()
    return text.strip().splitlines()[0] if text.strip() else ""


def plugins(group: str | None = None) -> list[dict[str, str]]:
    """List installed plugins: name, group, distribution, version, one-line description.

    A plugin that fails to import is listed with its error as description (it is not loaded
    by a run unless asked for by name).
    """
    rows = []
    for grp in [group_name(group)] if group else list(FAMILIES):
        for name, info in sorted(discover(grp).items()):
            try:
                desc = describe(load_plugin(grp, name))
            except PluginError as exc:
                desc = f"BROKEN: {exc}"
            rows.append(
                {
                    "name": name,
                    "group": grp,
                    "distribution": info.distribution,
                    "version": info.version,
                    "description": desc,
                }
            )
    return rows
