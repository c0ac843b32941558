"""Input and configuration checks shared by the embedders (errors name the problem and the fix)."""
from __future__ import annotations

import numpy as np

from pointatlas.errors import ConfigError, InputError
from pointatlas.pointcloud import check_distinct, validate_points


def check_points(X, *, min_points: int = 2, what: str = "points", reason: str = "") -> np.ndarray:
    """Return ``X`` as a finite, duplicate-free (N, D) float64 array with N >= ``min_points``.

    Raises :class:`InputError` for NaN/inf rows, duplicates or too few points.
    """
    X = validate_points(X, what=what)
    if X.shape[0] < min_points:
        raise InputError(
            f"{what}: need at least {min_points} points{reason}, got {X.shape[0]}. "
            "Give more points or lower n_neighbors."
        )
    check_distinct(X, what=what)
    return X


def check_int(name: str, value, *, low: int, high: int | None = None, fix: str = "") -> int:
    """Check that ``value`` is an integer in [low, high]; raise :class:`ConfigError` otherwise."""
    ok = isinstance(value, (int, np.integer)) and not isinstance(value, bool)
    if ok and value >= low and (high is None or value <= high):
        return int(value)
    rng = f">= {low}" if high is None else f"in [{low}, {high}]"
    raise ConfigError(f"{name}={value!r} is invalid: it must be an integer {rng}. {fix}".strip())


def check_float(name: str, value, *, low: float, high: float | None = None,
                low_open: bool = False, fix: str = "") -> float:
    """Check that ``value`` is a real number in [low, high] (or (low, high]); ConfigError otherwise."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = float("nan")
    ok = np.isfinite(v) and (v > low if low_open else v >= low) and (high is None or v <= high)
    if ok and not isinstance(value, bool):
        return v
    lo = f"> {low}" if low_open else f">= {low}"
    rng = lo if high is None else f"{lo} and <= {high}"
    raise ConfigError(f"{name}={value!r} is invalid: it must be a number {rng}. {fix}".strip())


def check_graph_params(n_neighbors, radius, n_points: int) -> None:
    """Exactly one of ``n_neighbors`` / ``radius`` defines the neighbour graph; check it fits N."""
    if (n_neighbors is None) == (radius is None):
        raise ConfigError(
            f"give exactly one of n_neighbors={n_neighbors!r} and radius={radius!r} "
            "(set the other to None)."
        )
    if n_neighbors is not None:
        check_int("n_neighbors", n_neighbors, low=1, fix="Typical values are 8-30.")
        if n_points < n_neighbors + 1:
            raise InputError(
                f"got {n_points} points but n_neighbors={n_neighbors} needs at least "
                f"{n_neighbors + 1}. Lower n_neighbors or give more points."
            )
    else:
        check_float("radius", radius, low=0.0, low_open=True,
                    fix="Use a few times the typical point spacing.")
