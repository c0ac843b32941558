"""pointatlas: compute on smooth manifolds known only through scattered points.

The core is small: plugin registry, config schemas, run pipeline, results I/O, run catalog,
reports and command-line tools. Heavy modules (xarray, numba, pyvista, matplotlib) are
imported only when used, so ``import pointatlas`` stays fast.
"""
from __future__ import annotations

from importlib import import_module

from .errors import ConfigError, InputError, PluginError, PointatlasError, SchemaError
from .registry import load_plugin, plugins, refresh

__version__ = "0.1.0"

_LAZY = {
    "open_run": "pointatlas.results",
    "open_sweep": "pointatlas.sweep",
    "write_results": "pointatlas.results",
    "PointCloud": "pointatlas.pointcloud",
    "BasisFunctions": "pointatlas.basis",
    "RunContext": "pointatlas.context",
}

__all__ = [
    "ConfigError",
    "InputError",
    "PluginError",
    "PointatlasError",
    "SchemaError",
    "load_plugin",
    "plugins",
    "refresh",
    "__version__",
    *_LAZY,
]


def __getattr__(name: str):
    if name in _LAZY:
        return getattr(import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'pointatlas' has no attribute {name!r}")
