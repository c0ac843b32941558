"""Shared machinery of the analytic surface generators: validation, markers, PointCloud.

A subclass's ``Config`` declares its parameter constraints (:data:`COMMON_CONSTRAINTS` plus its
own, checked by :func:`pointatlas.constraints.validate_parameters` at start-up and in
``load``). A subclass implements ``_check()`` (the rules that tie settings together),
``_sample(n, sampling, rng)`` returning ``(points (n, 3), parameters (n, 2))`` and
``_exact()`` (known exact quantities).
Markers (thesis §3.3) are a second, coarser sampling of the same surface with
``n_markers`` points, drawn with the same sampling scheme.
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np

from pointatlas.constraints import Interval, Options, validate_parameters
from pointatlas.errors import ConfigError
from pointatlas.pointcloud import PointCloud

SAMPLINGS = ("structured", "random")

#: a finite length > 0 (a radius, a side, a scale)
POSITIVE = [Interval(float, 0, None, closed="neither")]

#: the settings every generator has: the number of points, the sampling scheme (see each
#: class) and the size of a coarser marker set (None, or below n_points: checked with it)
COMMON_CONSTRAINTS = {
    "n_points": [Interval(int, 4, None)],
    "sampling": [Options(SAMPLINGS)],
    "n_markers": [Interval(int, 4, None), None],
}


def require(ok: bool, name: str, value, valid: str, fix: str) -> None:
    """Raise :class:`ConfigError` naming the value, the valid range and the fix."""
    if not ok:
        raise ConfigError(f"{name}={value!r} is invalid: {valid}. {fix}")


def check_rng(rng) -> None:
    """Raise :class:`ConfigError` unless ``rng`` is a numpy Generator."""
    if not isinstance(rng, np.random.Generator):
        raise ConfigError(f"rng must be a numpy.random.Generator, got "
                          f"{type(rng).__name__}. Pass numpy.random.default_rng(seed).")


class SurfaceSource:
    """Base of the analytic surfaces; not a plugin by itself."""

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
        """The declared constraints of the Config, and n_markers below n_points."""
        validate_parameters(self)
        n, m = self.n_points, self.n_markers
        require(
            m is None or m < n, "n_markers", m, f"must be None or an integer in [4, n_points={n})",
            "Markers are a coarser set; a common choice is n_markers ≈ n_points/4 "
            "(one refinement level coarser).",
        )

    def check_config(self) -> None:
        """The checks that need no sampling (run at start-up, before any work)."""
        self._check_common()
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
