"""Shared machinery of the analytic surface generators: validation, markers, PointCloud.

A subclass implements ``_check()`` (geometry validation), ``_sample(n, sampling, rng)``
returning ``(points (n, 3), parameters (n, 2))`` and ``_exact()`` (known exact quantities).
Markers (thesis §3.3) are a second, coarser sampling of the same surface with
``n_markers`` points, drawn with the same sampling scheme.
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np

from pointatlas.errors import ConfigError
from pointatlas.pointcloud import PointCloud

SAMPLINGS = ("structured", "random")

COMMON_CONSTRAINTS = {
    "n_points": "integer >= 4: number of points sampling the surface",
    "sampling": "'structured' (deterministic quasi-uniform lattice) or 'random' "
    "(independent, uniform with respect to surface area)",
    "n_markers": "None, or an integer in [4, n_points): size of a coarser marker set",
}


def require(ok: bool, name: str, value, valid: str, fix: str) -> None:
    """Raise :class:`ConfigError` naming the value, the valid range and the fix."""
    if not ok:
        raise ConfigError(f"{name}={value!r} is invalid: {valid}. {fix}")


def require_positive(name: str, value) -> None:
    require(
        isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value)
        and value > 0,
        name, value, "must be a finite number > 0", f"Set {name} to a positive length.",
    )


def check_rng(rng) -> None:
    """Raise :class:`ConfigError` unless ``rng`` is a numpy Generator."""
    if not isinstance(rng, np.random.Generator):
        raise ConfigError(f"rng must be a numpy.random.Generator, got "
                          f"{type(rng).__name__}. Pass numpy.random.default_rng(seed).")


class SurfaceSource:
    """Base of the analytic surfaces; not a plugin by itself."""

    parameter_constraints: ClassVar[dict[str, str]] = COMMON_CONSTRAINTS
    name: ClassVar[str] = "surface"
    intrinsic_dim: ClassVar[int] = 2

    # set by subclasses' __init__
    n_points: int
    sampling: str
    n_markers: int | None

    # -- to implement ---------------------------------------------------------------
    def _check(self) -> None:  # pragma: no cover - overridden
        pass

    def _sample(self, n: int, sampling: str, rng: np.random.Generator):
        raise NotImplementedError

    def _exact(self) -> dict[str, float]:
        return {}

    # -- shared ---------------------------------------------------------------------
    def _check_common(self) -> None:
        n = self.n_points
        require(
            isinstance(n, (int, np.integer)) and not isinstance(n, bool) and n >= 4,
            "n_points", n, "must be an integer >= 4", "Pass e.g. n_points=1000.",
        )
        require(
            self.sampling in SAMPLINGS, "sampling", self.sampling,
            f"must be one of {SAMPLINGS}", "Use sampling='structured' or sampling='random'.",
        )
        m = self.n_markers
        if m is not None:
            require(
                isinstance(m, (int, np.integer)) and not isinstance(m, bool) and 4 <= m < n,
                "n_markers", m, f"must be None or an integer in [4, n_points={n})",
                "Markers are a coarser set; a common choice is n_markers ≈ n_points/4 "
                "(one refinement level coarser).",
            )

    def check_config(self) -> None:
        """The checks that need no sampling (run at start-up, before any work)."""
        self._check_common()
        check_model = getattr(self, "_check_model", None)
        if callable(check_model):
            check_model()
        self._check()

    def load(self, rng: np.random.Generator) -> PointCloud:
        """Sample the surface; all randomness comes from ``rng``."""
        check_rng(rng)
        self._check_common()
        self._check()
        points, params = self._sample(int(self.n_points), self.sampling, rng)
        markers = None
        if self.n_markers is not None:
            markers, _ = self._sample(int(self.n_markers), self.sampling, rng)
        return PointCloud(
            points=points,
            markers=markers,
            intrinsic_dim=self.intrinsic_dim,
            exact=self._exact(),
            parameters=params,
            name=self.name,
        )
