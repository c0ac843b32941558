"""The :class:`Selector` a user writes in YAML (kept light: imported at start-up to register
configs); the selection itself is in :mod:`.selectors`."""
from __future__ import annotations

from dataclasses import dataclass, fields
from typing import List, Optional


@dataclass
class Selector:
    """Geometric criteria selecting points; all given criteria are AND-ed.

    plane: [nx, ny, nz, d] — points with |n·x − d| ≤ tol·|n|.
    box: [xmin, ymin, zmin, xmax, ymax, zmax] — points inside, enlarged by tol.
    expression: boolean expression of x, y, z, r, rho, theta, phi, at most 1000 characters
        and 50 levels deep (the functions and their arguments: ``expression.ALLOWED``).
    nearest_curve: [x, y, z] — the boundary curve nearest to this point.
    polyline: [[x, y, z], …] (two or more vertices) — points within tol of the polyline
        through them (e.g. a pre-existing crack).
    on_boundary: restrict to boundary points (default True).
    tol: length tolerance; None = 0.25 × median point spacing.
    name: label used in messages.
    """

    plane: Optional[List[float]] = None
    box: Optional[List[float]] = None
    expression: Optional[str] = None
    nearest_curve: Optional[List[float]] = None
    polyline: Optional[List[List[float]]] = None
    on_boundary: bool = True
    tol: Optional[float] = None
    name: str = "selector"


def describe(selector: Selector) -> str:
    """One-line description of the criteria, e.g. ``clamped (plane=[1, 0, 0, 5], on_boundary)``."""
    parts = [f"{f.name}={getattr(selector, f.name)!r}" for f in fields(selector)
             if f.name in ("plane", "box", "expression", "nearest_curve", "polyline", "tol")
             and getattr(selector, f.name) is not None]
    if selector.on_boundary:
        parts.append("on_boundary")
    return f"{selector.name} ({', '.join(parts) or 'no criterion'})"
