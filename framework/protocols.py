"""The small typed contracts every plugin family implements.

Each plugin is a class with a class attribute ``Config`` (a dataclass whose fields are the
keyword arguments of ``__init__``) and a one-line ``description``. The framework registers
``Config`` as a Hydra structured config under ``group=<family>, name=<plugin name>``.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Protocol, runtime_checkable

if TYPE_CHECKING:  # keep `import pointatlas` light
    import numpy as np
    import xarray as xr

    from .basis import BasisFunctions
    from .context import RunContext
    from .pointcloud import PointCloud


@runtime_checkable
class Plugin(Protocol):
    Config: ClassVar[type]
    description: ClassVar[str]


@runtime_checkable
class Source(Plugin, Protocol):
    """A point set: a generator (seeded through ``rng``) or a file reader."""

    def load(self, rng: np.random.Generator) -> PointCloud: ...


@runtime_checkable
class Embedder(Plugin, Protocol):
    """scikit-learn-style embedder: keyword-only ``__init__`` that only stores."""

    def fit(self, X: np.ndarray) -> Embedder: ...

    def fit_transform(self, X: np.ndarray) -> np.ndarray: ...


@runtime_checkable
class Approximant(Plugin, Protocol):
    """Meshfree basis functions on scattered nodes in d dimensions."""

    def fit(self, nodes: np.ndarray) -> Approximant: ...

    def evaluate(self, points: np.ndarray, order: int = 0) -> BasisFunctions: ...


@runtime_checkable
class Physics(Plugin, Protocol):
    """A physical model on an atlas (e.g. a Kirchhoff-Love shell); built from its Config."""

    def solve(self, ctx: RunContext, **inputs: Any) -> xr.Dataset: ...


@runtime_checkable
class Study(Plugin, Protocol):
    """What a run computes: reads the run context, returns the results Dataset.

    A study may also define ``report_figures(ds) -> list[(title, matplotlib.figure.Figure)]``
    and a dict ``references`` of published values its metrics are compared with.
    """

    def run(self, ctx: RunContext) -> xr.Dataset: ...
