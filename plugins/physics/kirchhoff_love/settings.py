"""What a user writes in config for a Kirchhoff–Love shell: material, supports, loads, solver.

Kept light (no numpy/scipy at import): these dataclasses are Hydra structured configs,
registered at start-up, so a misspelt key fails before any work with the valid keys listed.

Supports (Paper 1 App. D, thesis App. E.2), each on the points a :class:`Selector` picks:

========================  ===========================================================
``clamped``               u = 0 and the normal does not rotate, δn = 0
``simply_supported``      u = 0 (rotation free)
``symmetry``              u·e = 0 and u_,e ∥ e (the normal stays in the plane at any
                          rotation), e = ``normal`` of the symmetry plane
``diaphragm``             rigid diaphragm of plane normal e: u − (u·e)e = 0
``fixed``                 u_i = 0 for i in ``components`` (0, 1, 2 = x, y, z)
``displacement``          u_i = ``value[i]`` for i in ``components`` (default all three)
========================  ===========================================================

Loads: ``point`` (``force`` vector at the surface point nearest to ``at``), ``surface``
(``force`` per unit area, e.g. self weight), ``pressure`` (traction ``pressure``·n per unit
area, with the atlas's one orientation n: outward on a closed surface, towards
``atlas.orientation`` on an open one, where it is required), ``line`` (``force`` per unit
length on the boundary points ``where`` picks).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import List, Optional

from pointatlas.errors import ConfigError

from .selector_spec import Selector

SUPPORT_KINDS = ("clamped", "simply_supported", "symmetry", "diaphragm", "fixed", "displacement")
LOAD_KINDS = ("point", "surface", "pressure", "line")
SOLVERS = ("direct", "cg_ilu")


@dataclass
class Support:
    """An essential boundary condition on the points ``where`` selects (see module doc)."""

    kind: str = "clamped"
    where: Selector = field(default_factory=Selector)
    normal: Optional[List[float]] = None
    components: Optional[List[int]] = None
    value: Optional[List[float]] = None


@dataclass
class Load:
    """An external load (see module doc); ``force`` in force, force/area or force/length."""

    kind: str = "point"
    at: Optional[List[float]] = None
    force: Optional[List[float]] = None
    pressure: Optional[float] = None
    where: Optional[Selector] = None


@dataclass
class ShellSettings:
    """Material (St. Venant–Kirchhoff through the thickness), supports, loads and solver."""

    young_modulus: float = 1.0e6
    poisson_ratio: float = 0.3
    thickness: float = 0.1
    supports: List[Support] = field(default_factory=list)
    loads: List[Load] = field(default_factory=list)
    segment_points: int = 4          # Gauss points per boundary segment (0: collocate)
    ghost_layers: int = 2            # ghost node layers beyond the boundary (Paper 1 §4.1.2)
    solver: str = "direct"           # sparse direct (SuperLU) or CG with incomplete LU
    penalty: float = 1.0e6           # augmented-Lagrangian penalty, relative to diag(K)
    constraint_tol: float = 1.0e-10  # relative constraint violation to stop the AL loop
    max_load_offset: float = 0.5     # a point load may lie this many spacings off the surface


def check_settings(s) -> None:
    """Raise :class:`ConfigError` naming any invalid support, load or number and the fix."""
    for name in ("young_modulus", "thickness", "penalty", "constraint_tol", "max_load_offset"):
        v = getattr(s, name)
        if not (isinstance(v, (int, float)) and v == v and v > 0 and v != float("inf")):
            raise ConfigError(f"physics.{name} = {v!r} is invalid: it must be a finite number "
                              "> 0. Give a positive value.")
    if not -1.0 < s.poisson_ratio < 0.5:
        raise ConfigError(f"physics.poisson_ratio = {s.poisson_ratio!r} is invalid: it must lie "
                          "in (-1, 0.5).")
    if s.solver not in SOLVERS:
        raise ConfigError(f"physics.solver = {s.solver!r} is unknown; use one of {SOLVERS}.")
    if s.segment_points < 0:
        raise ConfigError(f"physics.segment_points = {s.segment_points} must be >= 0.")
    if s.ghost_layers < 0:
        raise ConfigError(f"physics.ghost_layers = {s.ghost_layers} must be >= 0.")
    if not s.supports:
        raise ConfigError("physics.supports is empty: the shell is not held anywhere, so its "
                          "stiffness is singular. Add e.g. {kind: clamped, where: {plane: "
                          "[1, 0, 0, 5.0]}}.")
    for i, sup in enumerate(s.supports):
        if sup.kind not in SUPPORT_KINDS:
            raise ConfigError(f"physics.supports[{i}].kind = {sup.kind!r} is unknown; use one "
                              f"of {SUPPORT_KINDS}.")
        if sup.kind in ("symmetry", "diaphragm") and (not sup.normal or len(sup.normal) != 3):
            raise ConfigError(f"physics.supports[{i}] ({sup.kind}) needs normal: [nx, ny, nz], "
                              "the normal of its plane.")
        if sup.components is not None and any(c not in (0, 1, 2) for c in sup.components):
            raise ConfigError(f"physics.supports[{i}].components = {sup.components} must be "
                              "a list of 0, 1, 2 (x, y, z).")
        if sup.kind == "fixed" and not sup.components:
            raise ConfigError(f"physics.supports[{i}] (fixed) needs components, e.g. [2].")
        if sup.kind == "displacement" and (not sup.value or len(sup.value) != 3):
            raise ConfigError(f"physics.supports[{i}] (displacement) needs value: [ux, uy, uz].")
    for i, ld in enumerate(s.loads):
        if ld.kind not in LOAD_KINDS:
            raise ConfigError(f"physics.loads[{i}].kind = {ld.kind!r} is unknown; use one of "
                              f"{LOAD_KINDS}.")
        if ld.kind == "pressure":
            if ld.pressure is None:
                raise ConfigError(f"physics.loads[{i}] (pressure) needs pressure: <value>.")
        elif not ld.force or len(ld.force) != 3:
            raise ConfigError(f"physics.loads[{i}] ({ld.kind}) needs force: [fx, fy, fz].")
        if ld.kind == "point" and (not ld.at or len(ld.at) != 3):
            raise ConfigError(f"physics.loads[{i}] (point) needs at: [x, y, z], the point "
                              "where the force acts.")
        if ld.kind == "line" and ld.where is None:
            raise ConfigError(f"physics.loads[{i}] (line) needs where: a boundary selector.")
    _check_expressions(s)


def _check_expressions(s) -> None:
    """Selector expressions are parsed and checked at start-up (nothing is evaluated)."""
    from .expression import parse_expression

    for label, items in (("supports", s.supports), ("loads", s.loads)):
        for i, item in enumerate(items):
            where = getattr(item, "where", None)
            expression = getattr(where, "expression", None) if where is not None else None
            if expression is None:
                continue
            try:
                parse_expression(expression)
            except ConfigError as exc:
                raise ConfigError(f"physics.{label}[{i}].where: {exc}") from None
