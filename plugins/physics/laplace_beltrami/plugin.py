"""−Δ_Γ u + c u = f on the atlas of a surface, written only against the physics kit.

The weak form is the minimum of Π[u] = ∫_Γ ½ a^αβ u_,α u_,β + ½ c u² − f u dΓ (the surface
gradient |∇_Γ u|² = a^αβ u_,α u_,β in a chart with metric a_αβ), one scalar field of order 1,
Dirichlet values u = g where ``supports`` select (augmented Lagrangian). Units: u that of
``source_term`` × length², c 1/length².
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, List

import numpy as np

from pointatlas.constraints import Interval, Options, Types
from pointatlas.stores_config import stores_config
from pointatlas_kit.fields import Field
from pointatlas_kit.linear_problem import LinearPhysics

U = Field("u", components=1, order=1, units="1", long_name="solution u of -Δu + c u = f")


@dataclass
class LaplaceBeltramiConfig:
    """c (1/length², ≥ 0), f as an expression of x, y, z, r, θ, φ; ``supports``: a list of
    {where: <selector>, value: <number or expression>} (Dirichlet); solver backend."""

    c: float = 1.0
    source_term: str = "0"
    supports: List[Any] = field(default_factory=list)
    ghost_layers: int = 2
    solver: str = "auto"
    penalty: float = 1.0e2          # AL penalty / mean diag K (as the shell's)
    constraint_tol: float = 1.0e-12
    parameter_constraints: ClassVar[dict] = {
        "c": [Interval(float, 0, None)], "source_term": [Types(str)],
        "ghost_layers": [Interval(int, 0, None)], "penalty": [Interval(float, 0, None, closed="neither")],
        "solver": [Options(("auto", "superlu", "pardiso", "cg_amg", "cg_ilu", "direct"))],
        "constraint_tol": [Interval(float, 0, 1, closed="neither")]}


class ScreenedDiffusion:
    """W = ½ a^αβ u_,α u_,β + ½ c u² (per area); jet (u, u_,1, u_,2), data (a^11, a^12, a^22)."""

    fields: ClassVar[tuple] = (U,)
    density_names: ClassVar[tuple] = ("gradient", "reaction")
    frame_invariant: ClassVar[bool] = False

    def __init__(self, c: float):
        self.c = float(c)

    def point_data(self, q):
        A = q.inverse_metric
        return np.column_stack([A[:, 0, 0], A[:, 0, 1], A[:, 1, 1]])

    def evaluate(self, jets, data, want):
        u, u1, u2 = jets.T
        a11, a12, a22 = data.T
        f1, f2 = a11 * u1 + a12 * u2, a12 * u1 + a22 * u2
        dens = np.column_stack([0.5 * (u1 * f1 + u2 * f2), 0.5 * self.c * u * u])
        g = np.column_stack([self.c * u, f1, f2]) if want >= 1 else None
        H = None
        if want >= 2:
            H = np.zeros((len(u), 3, 3))
            H[:, 0, 0], H[:, 1, 1], H[:, 2, 2] = self.c, a11, a22
            H[:, 1, 2] = H[:, 2, 1] = a12
        return dens, g, H


@stores_config
class LaplaceBeltrami(LinearPhysics):
    """Screened Poisson equation −Δ_Γ u + c u = f on a surface given by points."""

    Config = LaplaceBeltramiConfig
    fields: ClassVar[tuple] = (U,)
    description: ClassVar[str] = "−Δ_Γ u + c u = f on the atlas (the physics kit's scalar PDE)."
    #: Config values of a small problem for pointatlas.testing.check_physics (f = 1, u = 0 on
    #: the whole boundary of its open patch, which lies in [0, 1]² × [0, 0.35])
    conformance_case: ClassVar[dict] = {"c": 1.0, "source_term": "1", "supports": [
        {"where": {"box": [-1.0, -1.0, -1.0, 2.0, 2.0, 2.0]}, "value": 0.0}]}

    def energies(self, positions):
        from pointatlas_kit.energy import LinearSource
        from pointatlas_kit.expression import evaluate_values

        return [ScreenedDiffusion(self.c), LinearSource(U, evaluate_values(self.source_term,
                                                                           positions))]
