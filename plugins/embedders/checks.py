"""Checks shared by the embedders: the points, the rules that tie settings together or to the
data, and the parameter constraints several Configs declare (checked by
:func:`pointatlas.constraints.validate_parameters` in ``fit`` and at start-up)."""
from __future__ import annotations

import numpy as np

from pointatlas.constraints import Interval, Types
from pointatlas.errors import ConfigError, InputError
from pointatlas.pointcloud import check_distinct, validate_points

#: n_components >= 1 (and below the ambient dimension: checked in ``fit``, it needs the data)
COMPONENTS = {"n_components": [Interval(int, 1, None)]}
#: the neighbour graph: k nearest neighbours or a radius, exactly one of them not None
GRAPH = {"n_neighbors": [Interval(int, 1, None), None],
         "radius": [Interval(float, 0, None, closed="neither"), None]}
#: the affine isometric correction; aic_neighbors None: n_neighbors (or 12)
AIC = {"aic": [Types(bool)], "aic_neighbors": [Interval(int, 1, None), None]}


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


def check_components(n_components: int, X: np.ndarray, *, method: str = "the embedding") -> int:
    """``n_components`` d is below the number of features D (an embedding reduces the
    dimension) and below the number of points N (N centred points span at most N - 1
    dimensions); returns d."""
    d = int(n_components)
    n, D = X.shape
    if d >= D:
        fix = (f"Lower n_components to at most {D - 1}" if D > 1
               else "Give points with two or more coordinates")
        raise ConfigError(
            f"n_components={d} must be below the ambient dimension: the points have {D} "
            f"feature(s) (coordinates), so {method} cannot reduce their dimension. {fix}.")
    if d >= n:
        raise ConfigError(f"n_components={d} must be below the number of points ({n} "
                          f"sample(s)); lower n_components to at most {n - 1} or give more "
                          "points.")
    return d


def check_one_graph(n_neighbors, radius) -> None:
    """Exactly one of ``n_neighbors`` / ``radius`` defines the neighbour graph (each value's
    own range: the declared :data:`GRAPH` constraints)."""
    if (n_neighbors is None) == (radius is None):
        raise ConfigError(
            f"give exactly one of n_neighbors={n_neighbors!r} and radius={radius!r} "
            "(set the other to None)."
        )


def check_graph_fits(n_neighbors, n_points: int) -> None:
    """The k-NN graph needs N >= k + 1 points."""
    if n_neighbors is not None and n_points < n_neighbors + 1:
        raise InputError(
            f"got {n_points} points but n_neighbors={n_neighbors} needs at least "
            f"{n_neighbors + 1}. Lower n_neighbors or give more points."
        )
