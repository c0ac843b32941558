"""What a path follower needs from the equilibrium problem it is given: the protocol.

The path followers (:mod:`.load_control`, :mod:`.arc_length`, :mod:`.stable_equilibrium`,
:mod:`.branch_switching`, :mod:`.stability`) know no physics. The caller builds an object
with the members below (the shell's is ``pointatlas_physics.kirchhoff_love.equilibrium.
Equilibrium``) and passes it to :func:`.path_following.follow_path`. The problem is the
stationarity of the augmented Lagrangian of the total potential at a load factor λ,

    Π_ρ(U; μ, λ) = W(U) − λFᵀU + μᵀ(CU − λg) + ½ρ|CU − λg|²,

with W the strain energy, F the reference load, C U = λg the linear constraints (loads and
imposed values both scale with λ) and μ their multipliers; the out-of-balance force at
ρ-feasible points is R = ∂W/∂U − λF + Cᵀμ. Units are the caller's: U length, forces force,
energies energy (so that λ is dimensionless).

Which members are used where: all path followers use ``F, C, g, rho, residual, scale,
system, energy_parts, n_components, row_support``; ``merit`` only with a line search or
``stable_path`` (Armijo on Π_ρ); ``lbfgs`` only with ``lbfgs_iterations > 0``;
``length_scale`` only with ``stable_path`` (the kick off a saddle); ``arc_mask`` only under
arc-length control and in branch switching.
"""
from __future__ import annotations

from typing import Optional, Protocol

import numpy as np

from .augmented_lagrangian import ConstrainedSystem


class EquilibriumProblem(Protocol):
    """The equilibrium problem of a path follower (module doc). n = number of DOFs,
    c = number of constraint rows."""

    #: (n,) reference load F (force); the applied load is λF.
    F: np.ndarray
    #: (c, n) scipy sparse constraint matrix C of C U = λ g.
    C: object
    #: (c,) reference right-hand side g of the constraints (length); scaled by λ.
    g: np.ndarray
    #: penalty ρ of the last :meth:`system` (None before the first): set by :meth:`system`,
    #: read by the L-BFGS stage, the Armijo test and the saved path state.
    rho: Optional[float]
    #: components per node: an increment's U is reported as (n / n_components,
    #: n_components) and each support's reaction as an (n_components,) resultant.
    n_components: int
    #: (c,) int: the support (0, 1, …) each constraint row belongs to (for the reactions).
    row_support: np.ndarray
    #: (n,) 1 on the DOFs the arc length |ΔU| measures, 0 on the others (e.g. nearly free
    #: ghost DOFs that would dominate |ΔU| with motions that do not change the body).
    arc_mask: np.ndarray
    #: size of the body (length): floor of the kick off a saddle is 1e-3 of it.
    length_scale: float

    def residual(self, U: np.ndarray, mu: np.ndarray, lam: float) -> tuple[np.ndarray, float]:
        """(R, W): the out-of-balance force R = ∂W/∂U − λF + Cᵀμ (n,) and the energy W(U)."""

    def scale(self, lam: float, mu: np.ndarray) -> float:
        """Force scale of the residual (> 0): e.g. |λF|, or |Cᵀμ| when F = 0."""

    def merit(self, W: float, U: np.ndarray, mu: np.ndarray, lam: float) -> float:
        """Π_ρ(U; μ, λ) given W = W(U) (energy)."""

    def system(self, U: np.ndarray, shift: float = 0.0) -> ConstrainedSystem:
        """The factorised constrained tangent ∂²W/∂U²(U) + shift·I + ρCᵀC; sets :attr:`rho`.
        A call may take over the factorisation of the system the previous call returned
        (``ConstrainedSystem(..., reuse=)``): the path followers never solve with a system
        after asking for the next one."""

    def lbfgs(self, U: np.ndarray, mu: np.ndarray, lam: float, rel_tol: float,
              max_iter: int, log=None) -> tuple[np.ndarray, int]:
        """A coarse minimiser of Π_ρ(·; μ, λ) from U, to |∇Π_ρ| ≤ rel_tol·scale, and its
        iteration count (U unchanged and 0 if it cannot improve)."""

    def energy_parts(self, U: np.ndarray) -> dict:
        """Named parts of the energy at U reported with each increment, e.g. {'total': …}."""
