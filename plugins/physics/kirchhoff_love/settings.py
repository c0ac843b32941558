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
from typing import ClassVar, List, Optional

from pointatlas.constraints import Each, Interval, Options, Types, validate_parameters
from pointatlas.errors import ConfigError

from pointatlas_kit.selector_spec import Selector

SUPPORT_KINDS = ("clamped", "simply_supported", "symmetry", "diaphragm", "fixed", "displacement")
LOAD_KINDS = ("point", "surface", "pressure", "line")
SOLVERS = ("direct", "cg_ilu", "superlu", "pardiso", "cg_amg", "auto")  # pointatlas_solvers

#: a point or a vector in R^3: three finite numbers
VECTOR = Each(Interval(float), length=3)
_POSITIVE = [Interval(float, 0, None, closed="neither")]


@dataclass
class Support:
    """An essential boundary condition on the points ``where`` selects (see module doc)."""

    kind: str = "clamped"
    where: Selector = field(default_factory=Selector)
    normal: Optional[List[float]] = None
    components: Optional[List[int]] = None
    value: Optional[List[float]] = None

    # what each kind needs (normal, components, value) is checked in check_settings
    parameter_constraints: ClassVar[dict[str, list]] = {
        "kind": [Options(SUPPORT_KINDS)],
        "normal": [VECTOR, None],
        "components": [Each(Options((0, 1, 2))), None],   # x, y, z
        "value": [VECTOR, None],
    }


@dataclass
class Load:
    """An external load (see module doc); ``force`` in force, force/area or force/length."""

    kind: str = "point"
    at: Optional[List[float]] = None
    force: Optional[List[float]] = None
    pressure: Optional[float] = None
    where: Optional[Selector] = None

    # what each kind needs (at, force, pressure, where) is checked in check_settings
    parameter_constraints: ClassVar[dict[str, list]] = {
        "kind": [Options(LOAD_KINDS)],
        "at": [VECTOR, None],
        "force": [VECTOR, None],
        "pressure": [Interval(float), None],
    }


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
    solver: str = "auto"             # pointatlas_solvers backend: auto = PARDISO if installed, else SuperLU
    penalty: float = 1.0e2           # augmented-Lagrangian penalty, relative to mean diag K:
    #                                  10² keeps K + ρCᵀC conditioned (SuperLU and PARDISO agree
    #                                  to 2e-8 on the hemisphere, 4e-5 with 10⁶) while the dual
    #                                  CG of the AL loop still meets constraint_tol in 1-3 solves
    constraint_tol: float = 1.0e-10  # relative constraint violation to stop the AL loop
    max_load_offset: float = 0.5     # a point load may lie this many spacings off the surface
    # the linear analysis without the basis kept: chart groups rebuild it, assemble K and drop
    # it (pointatlas_kit.streamed_tangent): ~0.25 MB less per point, about twice the assembly
    # time; point and line loads only (a surface load integrates over the kept basis)
    streamed_assembly: bool = False

    parameter_constraints: ClassVar[dict[str, list]] = {
        "young_modulus": _POSITIVE,
        "poisson_ratio": [Interval(float, -1, 0.5, closed="neither")],
        "thickness": _POSITIVE,
        "segment_points": [Interval(int, 0, None)],
        "ghost_layers": [Interval(int, 0, None)],
        "solver": [Options(SOLVERS)],
        "penalty": _POSITIVE,
        "constraint_tol": _POSITIVE,
        "max_load_offset": _POSITIVE,
        "streamed_assembly": [Types(bool)],
    }


def check_settings(s) -> None:
    """Raise :class:`ConfigError` naming any invalid number, choice, support or load and the
    fix: every value against its declared constraints (``parameter_constraints`` of
    :class:`ShellSettings`, :class:`Support`, :class:`Load`), then what each kind of support
    and load needs."""
    validate_parameters(s, ShellSettings.parameter_constraints, prefix="physics")
    if not s.supports:
        raise ConfigError("physics.supports is empty: the shell is not held anywhere, so its "
                          "stiffness is singular. Add e.g. {kind: clamped, where: {plane: "
                          "[1, 0, 0, 5.0]}}.")
    for i, sup in enumerate(s.supports):
        validate_parameters(sup, Support.parameter_constraints, prefix=f"physics.supports[{i}]")
        if sup.kind in ("symmetry", "diaphragm") and sup.normal is None:
            raise ConfigError(f"physics.supports[{i}] ({sup.kind}) needs normal: [nx, ny, nz], "
                              "the normal of its plane.")
        if sup.kind == "fixed" and not sup.components:
            raise ConfigError(f"physics.supports[{i}] (fixed) needs components, e.g. [2].")
        if sup.kind == "displacement" and sup.value is None:
            raise ConfigError(f"physics.supports[{i}] (displacement) needs value: [ux, uy, uz].")
    for i, ld in enumerate(s.loads):
        validate_parameters(ld, Load.parameter_constraints, prefix=f"physics.loads[{i}]")
        if ld.kind == "pressure":
            if ld.pressure is None:
                raise ConfigError(f"physics.loads[{i}] (pressure) needs pressure: <value>.")
        elif ld.force is None:
            raise ConfigError(f"physics.loads[{i}] ({ld.kind}) needs force: [fx, fy, fz].")
        if ld.kind == "point" and ld.at is None:
            raise ConfigError(f"physics.loads[{i}] (point) needs at: [x, y, z], the point "
                              "where the force acts.")
        if ld.kind == "line" and ld.where is None:
            raise ConfigError(f"physics.loads[{i}] (line) needs where: a boundary selector.")
        if s.streamed_assembly and ld.kind in ("surface", "pressure"):
            raise ConfigError(f"physics.loads[{i}] ({ld.kind}) needs the basis at the Gauss "
                              "points, which physics.streamed_assembly=true does not keep: "
                              "remove streamed_assembly or use point and line loads.")
    _check_expressions(s)


def _check_expressions(s) -> None:
    """Selector expressions are parsed and checked at start-up (nothing is evaluated)."""
    from pointatlas_kit.expression import parse_expression

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
