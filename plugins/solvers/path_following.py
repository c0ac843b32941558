"""Follow the equilibrium path of a problem the caller gives: load or arc-length control.

:func:`follow_path` dispatches on ``path.control``: ``'load'`` (force or displacement
control, :mod:`.load_control`; with ``stable_path`` by descent to stable states) or
``'arc_length'`` (Crisfield's cylindrical arc length, :mod:`.arc_length`, through limit
points and, with ``branch_switching``, onto secondary branches). The equilibrium problem
``eq`` is built by the caller (:class:`.equilibrium_problem.EquilibriumProblem`; for the
shell, ``pointatlas_physics.kirchhoff_love.equilibrium.Equilibrium``).
"""
from __future__ import annotations

from typing import Callable, Optional

from .arc_length import follow_arc_length
from .increment import Increment, PathSettings
from .load_control import follow_load_control
from .path_state import PathStart

CONTROLS = ("load", "arc_length")


def follow_path(eq, path: PathSettings,
                on_increment: Optional[Callable[[Increment], None]] = None, log=None,
                start: Optional[PathStart] = None) -> list[Increment]:
    """Increments of ``eq`` from λ = 0 (or from ``start``, the increments of an interrupted
    run and the state after them) to ``path.max_load_factor``, by the control
    ``path.control``; ``on_increment`` is called with each new increment (e.g. to save it).
    Returns the new increments; raises :class:`.increment.PathFollowingError` (the
    increments reported so far stand) when the path cannot be followed further."""
    if path.control == "arc_length":
        return follow_arc_length(eq, path, on_increment, log, start)
    if path.control != "load":
        raise ValueError(f"unknown control {path.control!r}: use one of {CONTROLS}")
    return follow_load_control(eq, path, on_increment, log, start)
