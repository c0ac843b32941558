"""What a user writes in config for a fracturing Kirchhoff–Love shell.

The shell's material, supports, loads and solver (:mod:`pointatlas_physics.kirchhoff_love.
settings`, the same keys), plus the phase field (notation of the thesis §4 and Amiri et al.
2014; :mod:`.phase_field`):

=======================  ==================================================================
``fracture_toughness``   G_c (energy/length², J/m²): crack energy per crack surface area
``length_scale``         κ̄ (length): the band width; ℓ = 2κ̄ in the AT2 form. Must span a
                         few point spacings (:data:`MIN_SPACINGS`)
``residual_stiffness``   η_κ̄ in (0, 1): stiffness kept by broken material, g(0) = η_κ̄
``crack_model``          ``at2`` (the thesis: (1 − υ)²/(4κ̄), no elastic phase: any strain
                         energy lowers υ) or ``at1`` ((1 − υ) linear: intact, υ = 1, below
                         the threshold ψ_c = 3G_c h/(32κ̄) of the driving energy), both with
                         crack energy G_c h per crack length (:mod:`.phase_field`)
``split``                ``none`` (the thesis: all of W degraded), or ``amor``: only the
                         tensile part of the strain energy at points through the thickness
                         is degraded and drives the crack (Amor et al. 2009, Kiendl et al.
                         2016; :mod:`.amor_split`); needs ``kinematics: linear`` (it
                         splits the linear strains)
``thickness_points``     Gauss–Legendre points through the thickness of the ``amor`` split
``kinematics``           ``linear`` (the shell's linear kinematics), ``nonlinear`` (the
                         shell's geometrically exact energy, Newton in each displacement
                         step), or ``none``: the phase field alone with no driving energy
                         (the crack-band check)
``precracks``            selectors ({polyline: …, tol: …}, {box: …}, {expression: …}) of
                         points held at υ = 0 throughout (on_boundary defaults to false)
``staggered_tol``        staggered iterations stop when max |Δυ| < this
``max_staggered``        cap on staggered iterations per increment (reached: refused)
``scheme``               ``staggered`` (alternate minimisation), or ``monolithic``: Newton
                         on both fields with the coupled tangent first, the staggered
                         iteration where that gives up (:mod:`.monolithic`); needs
                         ``split: none``
``newton_tol``           ``nonlinear`` and ``monolithic``: a displacement step's Newton stops at |R| ≤ this ×
                         the force scale (the reactions, or the load)
``max_newton``           ``nonlinear`` and ``monolithic``: cap on its Newton iterations (reached: refused)
=======================  ==================================================================
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, List, Optional

from pointatlas.constraints import Interval, Options, validate_parameters
from pointatlas.errors import ConfigError

from pointatlas_physics.kirchhoff_love.settings import ShellSettings

from .phase_field import CRACK_MODELS

SPLITS = ("none", "amor")
SCHEMES = ("staggered", "monolithic")
KINEMATICS = ("linear", "nonlinear", "none")
#: κ̄ must be at least this many median point spacings: below it the band 1 − υ = e^{−|x|/2κ̄}
#: is not resolved (measured in tests/.../test_crack_band.py: the profile error is
#: 2-4 % at 2 spacings, 8 % at 1)
MIN_SPACINGS = 2.0
_POSITIVE = [Interval(float, 0, None, closed="neither")]


@dataclass
class FractureSettings(ShellSettings):
    """The shell's settings plus the phase field's (module doc)."""

    kinematics: str = "linear"
    fracture_toughness: float = 1.0
    length_scale: Optional[float] = None
    residual_stiffness: float = 1.0e-6
    crack_model: str = "at2"
    split: str = "none"
    thickness_points: int = 5
    precracks: List[Any] = field(default_factory=list)
    staggered_tol: float = 1.0e-4
    max_staggered: int = 200
    scheme: str = "staggered"
    newton_tol: float = 1.0e-9
    max_newton: int = 25

    parameter_constraints: ClassVar[dict[str, list]] = {
        **ShellSettings.parameter_constraints,
        "kinematics": [Options(KINEMATICS)],
        "fracture_toughness": _POSITIVE,
        "length_scale": [*_POSITIVE, None],   # None: refused with its own message (required)
        "residual_stiffness": [Interval(float, 0, 1, closed="neither")],
        "crack_model": [Options(tuple(CRACK_MODELS))],
        "split": [Options(SPLITS)],
        "thickness_points": [Interval(int, 2, None)],
        "staggered_tol": [Interval(float, 0, 1, closed="neither")],
        "max_staggered": [Interval(int, 1, None)],
        "scheme": [Options(SCHEMES)],
        "newton_tol": [Interval(float, 0, 1, closed="neither")],
        "max_newton": [Interval(int, 1, None)],
    }


def check_fracture_settings(s: FractureSettings) -> None:
    """ConfigError naming any invalid value and the fix, before any work: the declared
    constraints, then what the shell needs when it is loaded (supports and loads as the shell
    checks them) and the pre-crack selectors' form. The check of κ̄ against the cloud's
    spacing is :func:`check_length_scale`, once the points are known."""
    if s.length_scale is None:
        raise ConfigError("physics.length_scale (κ̄) is not set: give the crack band width in "
                          f"length units, at least {MIN_SPACINGS:g} point spacings, e.g. "
                          "physics.length_scale=0.02.")
    validate_parameters(s, FractureSettings.parameter_constraints, prefix="physics")
    if s.kinematics == "nonlinear" and s.split != "none":
        raise ConfigError(f"physics.split={s.split} splits the linear strains, and "
                          "kinematics=nonlinear has Green-Lagrange ones: set physics.split=none "
                          "with kinematics=nonlinear, or physics.kinematics=linear with the "
                          "split.")
    if s.scheme == "monolithic" and s.split != "none":
        raise ConfigError(f"physics.scheme=monolithic has no coupled tangent for "
                          f"physics.split={s.split}: set physics.scheme=staggered with the split, "
                          "or physics.split=none.")
    if s.scheme == "monolithic" and s.kinematics == "none":
        raise ConfigError("physics.scheme=monolithic couples the shell and the phase field, and "
                          "kinematics=none has no shell: set physics.scheme=staggered, or "
                          "physics.kinematics=linear.")
    if s.kinematics != "none":
        from pointatlas_physics.kirchhoff_love.settings import check_settings

        check_settings(s)
    elif s.split != "none":
        raise ConfigError(f"physics.split={s.split} splits the strain energy that drives the "
                          "crack, and kinematics=none has none: set physics.split=none, or "
                          "physics.kinematics=linear.")
    elif s.supports or s.loads:
        raise ConfigError("physics.kinematics=none solves the phase field alone: its supports "
                          "and loads would be ignored. Remove them, or set kinematics=linear.")
    for i, p in enumerate(precrack_selectors(s)):
        _check_selector(p, i)


def precrack_selectors(s: FractureSettings) -> list:
    """The pre-crack selectors as kit Selectors (``on_boundary`` false unless given)."""
    from pointatlas_kit.selector_spec import Selector

    out = []
    for i, p in enumerate(s.precracks):
        if isinstance(p, Selector):
            out.append(p)
            continue
        try:
            d = dict(p)
        except (TypeError, ValueError):
            raise ConfigError(f"physics.precracks[{i}] = {p!r} must be a selector, e.g. "
                              "{polyline: [[0.3, 0.5, 0], [0.7, 0.5, 0]]}.") from None
        keys = {f for f in Selector.__dataclass_fields__}
        bad = sorted(set(d) - keys)
        if bad:
            raise ConfigError(f"physics.precracks[{i}] has unknown key(s) {bad}; a selector "
                              f"takes {sorted(keys)}.")
        out.append(Selector(**{"on_boundary": False, "name": f"physics.precracks[{i}]", **d}))
    return out


def _check_selector(sel, i: int) -> None:
    from pointatlas_kit.selectors import CRITERIA, polyline_vertices

    if all(getattr(sel, c) is None for c in CRITERIA):
        raise ConfigError(f"physics.precracks[{i}] has no criterion: give one of "
                          f"{', '.join(CRITERIA)}, e.g. polyline: [[x0, y0, z0], [x1, y1, z1]].")
    if sel.polyline is not None:
        polyline_vertices(sel)
    if sel.expression is not None:
        from pointatlas_kit.expression import parse_expression

        try:
            parse_expression(sel.expression)
        except ConfigError as exc:
            raise ConfigError(f"physics.precracks[{i}]: {exc}") from None


def check_length_scale(length_scale: float, spacing: float, name: str) -> None:
    """ConfigError when κ̄ is below :data:`MIN_SPACINGS` × the cloud's median spacing."""
    smallest = MIN_SPACINGS * spacing
    if length_scale < smallest:
        raise ConfigError(
            f"physics.length_scale = {length_scale:g} is too small for {name}: the crack band "
            f"(about ±4κ̄ wide) must span at least {MIN_SPACINGS:g} point spacings "
            f"(median spacing {spacing:.4g}), so the smallest κ̄ this cloud supports is "
            f"{smallest:.4g}. Raise physics.length_scale, or sample the surface more densely "
            f"(about {(spacing / (length_scale / MIN_SPACINGS)) ** 2:.3g}× the points).")
