"""Staggered minimisation of the fracturing shell at an imposed-displacement factor (and,
with ``scheme: monolithic``, the hand-over to :mod:`.monolithic` first).

At each increment t (supports C U = t g, loads t F; Amiri et al. 2014 §3, Miehe et al. 2010
"alternate minimisation"), starting from the previous increment's phase field V_prev:

1. displacement step: U = argmin_U ∫ g(υ) W(U) − t Fᵀ U subject to C U = t g, with
   g(υ_q) = υ_q² + η_κ̄ frozen at the points (:class:`.degraded_energy.DegradedEnergy` of
   the shell energy, linearised for ``kinematics: linear``, a quadratic solved at once by
   the augmented Lagrangian; for ``kinematics: nonlinear`` the geometrically exact energy,
   minimised by the shared solvers' Newton with line search (:func:`pointatlas_solvers.
   increment.load_increment` on the shell's :class:`Equilibrium` of the degraded energy)
   from the previous iterate, to ``newton_tol``; its checked count of negative eigenvalues
   of the tangent (0: a minimum in u at the frozen υ) is kept per increment);
2. phase step: V = argmin_V crack energy + ∫ (υ² + η) ψ with ψ_q = W(U)_q the undegraded
   energy density, subject to V ≤ V_prev (:mod:`.phase_solve`; the pre-cracks, held in
   the initial state, stay broken by it);

repeated until max |ΔV| < ``staggered_tol`` (nodal values, υ being dimensionless), at most
``max_staggered`` times: an increment that does not converge is refused
(:class:`StaggeredNotConverged`, naming the change reached), never returned as converged.
Each step decreases Π, so the iteration is monotone; its count per increment is in the
results. (Anderson mixing of the staggered fixed point was tried and dropped: on the
441-point centre-cracked plate at its crack jump, depth 1 took 39 iterations against 60
plain and depth 3 did not converge in 60.)
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from pointatlas_solvers.increment import PathFollowingError

#: outside an at2 pre-crack's band: υ₀ ≥ this (:meth:`StaggeredProblem.away_from_precracks`)
AWAY_AT2 = 0.95
#: outside an at1 pre-crack's (compact) band: 1 − υ₀ below this. The initial solve holds the
#: pre-crack rows to a tolerance and leaves 1 − υ₀ = O(1e-9) far from them (1.5e-9 measured
#: on a 2 378-point Poisson-disk plate), while inside the band 1 − υ₀ = (1 − d/4κ̄)² > 1e-6
#: up to 0.999 of its width
INTACT = 1e-6


@dataclass
class FractureState:
    """A converged increment (or the initial state, factor 0)."""

    factor: float
    displacement_nodal: np.ndarray     # (n_nodes, 3) U
    phase_nodal: np.ndarray            # (n_nodes,) V
    multipliers: np.ndarray            # (rows,) of the supports (reactions −Cᵀμ)
    staggered_iterations: int
    energy: dict = field(default_factory=dict)   # elastic, fracture, load_work (energy)
    reactions: np.ndarray | None = None          # (n_supports, 3) resultant forces
    changes: list = field(default_factory=list)  # max |ΔV| after each staggered iteration
    #: checked negative eigenvalues of the last displacement step's tangent (nonlinear
    #: kinematics; 0 for the linear ones, whose degraded energy is convex)
    negative_modes: int = 0
    #: Newton iterations of the monolithic solve (0: the staggered scheme solved it)
    monolithic_iterations: int = 0


class StaggeredNotConverged(PathFollowingError):
    """The staggered iteration of an increment did not reach its tolerance (the states of
    the increments before it are unaffected: a path follower may cut the step)."""


class CrackJumped(PathFollowingError):
    """A staggered iterate's elastic energy fell below the caller's ``jump_floor``: the crack
    jumps within this step, and the caller (which would reject the converged increment for
    that drop) cuts the step without waiting for the iteration to converge."""

    def __init__(self, message, elastic, iteration):
        super().__init__(message)
        self.elastic, self.iteration = elastic, iteration


class StaggeredProblem:
    """The built, supported and loaded fracture problem of one surface model."""

    def __init__(self, model, settings, precrack_nodes, log=None):
        from scipy.sparse import diags

        from pointatlas_kit.assembler import Assembler
        from pointatlas_kit.fields import FieldLayout
        from pointatlas_kit.surface_model import ghost_springs
        from pointatlas_physics.kirchhoff_love.analysis import ShellModel, assemble_loads, \
            assemble_supports
        from pointatlas_physics.kirchhoff_love.material import ShellMaterial
        from pointatlas_physics.kirchhoff_love.shell_energy import ShellEnergy

        from .degraded_energy import DegradedEnergy, Linearized
        from .phase_solve import PhaseProblem

        s = self.settings = settings
        self.model, self.log, self.precrack_nodes = model, log, precrack_nodes
        material = ShellMaterial(young_modulus=s.young_modulus, poisson_ratio=s.poisson_ratio,
                                 thickness=s.thickness)
        material.check()
        shell = ShellModel(model.points, model.nodes, model.boundary, model.curves,
                           model.spacing, model.atlas, model.quadrature, model.times,
                           material=material)
        self.constraints = assemble_supports(shell, s)
        self.F = assemble_loads(shell, s, log).ravel()
        base = ShellEnergy(s.young_modulus, s.poisson_ratio, s.thickness)
        if s.split == "amor":
            from .amor_split import AmorSplitShellEnergy

            self.energy_u = AmorSplitShellEnergy(s.young_modulus, s.poisson_ratio, s.thickness,
                                                 s.thickness_points)
        elif s.kinematics == "nonlinear":
            self.energy_u = DegradedEnergy(base)
        else:
            self.energy_u = DegradedEnergy(Linearized(base))
        self.layout_u = FieldLayout(base.fields, model.nodes.shape[0])
        self.assembler_u = Assembler(model.quadrature, self.layout_u, [self.energy_u])
        K0 = self.assembler_u.tangent(np.zeros(self.layout_u.n_dofs))
        self.springs = diags(ghost_springs(K0.diagonal(), model, 3))
        if s.kinematics == "nonlinear":
            from pointatlas_physics.kirchhoff_love.equilibrium import Equilibrium

            # the shell's equilibrium problem on the degraded energy (its ghost springs are
            # those above: both from the intact tangent at U = 0)
            self.equilibrium = Equilibrium(shell, s, self.F, self.constraints,
                                           assembler=self.assembler_u)
        self.phase = PhaseProblem(model, s, precrack_nodes)
        self.interpolation = model.quadrature.interpolation()
        #: (support index, imposed displacement at factor 1 (3,)) of 'displacement' supports
        self.imposed = [(k, np.asarray(sup.value, float)) for k, sup in enumerate(s.supports)
                        if sup.kind == "displacement"]

    def initial_state(self) -> FractureState:
        """Factor 0: no displacement; the phase field of the pre-cracks alone (ψ = 0)."""
        n = self.model.nodes.shape[0]
        step = self.phase.solve(None, np.ones(n))
        return FractureState(0.0, np.zeros((n, 3)), step.nodal,
                             np.zeros(self.constraints.matrix.shape[0]), 0,
                             {"elastic": 0.0, "fracture": step.energy["fracture"],
                              "load_work": 0.0}, None, [])

    def displacement_step(self, V, factor, U0=None, mu0=None):
        """(U (n_nodes, 3), μ, ψ (m,), negative modes) at frozen phase field V; ψ the
        undegraded driving density (all of W, or its tensile part with ``split: amor``).
        ``U0`` (and ``mu0``, the supports' multipliers) start the Newton iteration of the
        split or of the nonlinear kinematics (a previous solution); the linear kinematics
        without a split ignore them."""
        s = self.settings
        g = self._degrade(V)
        negative = 0
        if s.split == "amor":
            U, mu = self._split_newton(factor, U0)
            psi = self.energy_u.driving(self.assembler_u.densities(U), g)
        elif s.kinematics == "nonlinear":
            U, mu, negative = self._nonlinear_newton(factor, U0, mu0)
            psi = self.assembler_u.densities(U).sum(axis=1) / g
        else:
            U, mu = self._quadratic_solve(self.assembler_u.tangent(
                np.zeros(self.layout_u.n_dofs)), factor)
            psi = self.assembler_u.densities(U).sum(axis=1) / g
        return U.reshape(-1, 3), mu, np.maximum(psi, 0.0), negative

    def _degrade(self, V):
        """Set the displacement energy's degradation to g(υ) of V at the points; g (m,)."""
        from .phase_field import degradation

        g = degradation(self.interpolation @ V, self.settings.residual_stiffness)
        self.energy_u.degradation = g
        self.assembler_u.refresh_data()
        return g

    def _nonlinear_newton(self, factor, U0, mu0):
        """(U, μ, checked negative eigenvalues) of the degraded geometrically exact energy at
        ``factor``: the shared Newton with line search from (U0, μ0) (module doc); refused
        (:class:`StaggeredNotConverged`) when it does not reach ``newton_tol`` in
        ``max_newton`` iterations."""
        from pointatlas_solvers.increment import PathSettings, load_increment

        s, eq = self.settings, self.equilibrium
        n = self.layout_u.n_dofs
        U = np.zeros(n) if U0 is None else np.asarray(U0, float).ravel()
        mu = np.zeros(eq.C.shape[0]) if mu0 is None else np.asarray(mu0, float)
        path = PathSettings(max_newton=s.max_newton, tol=s.newton_tol, line_search=True)
        out = load_increment(eq, path, U, mu, float(factor))
        if out is None:
            raise StaggeredNotConverged(
                f"the Newton iteration of a displacement step (kinematics=nonlinear) did not "
                f"converge at imposed-displacement factor {factor:.6g} in {s.max_newton} "
                f"iterations to newton_tol {s.newton_tol:g}. Take smaller increments, or raise "
                "physics.max_newton.")
        U, mu, _, _, negative = out
        return U, mu, int(negative)

    def _quadratic_solve(self, K, factor):
        """argmin ½ Uᵀ(K + springs)U − t Fᵀ U subject to C U = t g (augmented Lagrangian).
        The system of the previous call is handed on (``reuse``): every displacement step
        has the same sparsity pattern, so PARDISO factorises without a new analysis."""
        from pointatlas_solvers.augmented_lagrangian import ConstrainedSystem

        s, cons = self.settings, self.constraints
        system = ConstrainedSystem((K + self.springs).tocsr(), cons.matrix, s.penalty,
                                   s.constraint_tol, backend=s.solver,
                                   reuse=getattr(self, "_last_system", None))
        self._last_system = system
        U, mu, _ = system.solve(factor * self.F, factor * cons.rhs)
        return U, mu

    def _split_newton(self, factor, U0):
        """The displacement step of the amor split (:func:`.split_newton.minimise_split`)."""
        from .split_newton import minimise_split

        return minimise_split(self, factor, U0)

    def increment(self, state: FractureState, factor: float,
                  jump_floor: float | None = None) -> FractureState:
        """The converged solution at ``factor`` from ``state``: staggered (module doc), or
        first the monolithic Newton of :mod:`.monolithic` with ``scheme: monolithic``, the
        staggered iteration taking over from the same state where that gives up.

        ``jump_floor`` (energy; None: no check): when the elastic energy of a staggered
        iterate (U_k at the degradation of V_{k−1}, what the increment would report were it
        to stop at iterate k) falls below it, :class:`CrackJumped` is raised at once. A path
        follower that rejects increments whose elastic energy drops below a floor passes
        it, and a step whose crack jumps costs a few iterations instead of a converged
        staggered solve that is thrown away (at a jump the iteration takes 30–120 of them).
        Under displacement control the iterates' elastic energy falls as the crack grows, so
        an iterate below the floor announces a converged increment below it; were it to
        recover, the step is only cut more finely than needed (the path stays valid)."""
        s, started = self.settings, time.perf_counter()
        if s.scheme == "monolithic":
            from .monolithic import MonolithicNewton, MonolithicNotConverged

            if getattr(self, "_monolithic", None) is None:
                self._monolithic = MonolithicNewton(self)
            try:
                U, V, mu, its = self._monolithic.solve(state, factor)
            except MonolithicNotConverged as exc:
                if self.log is not None:
                    self.log.info("%s: staggered from the same state", exc)
            else:
                self._degrade(V)
                fracture = self.phase.assembler.energy(V)["fracture"]
                return self._state(factor, U, V, mu, 0, [], 0, fracture, started, its)
        upper = state.phase_nodal
        V, changes = upper.copy(), []
        U_warm, mu_warm = state.displacement_nodal, state.multipliers
        for it in range(1, s.max_staggered + 1):
            U, mu, psi, negative = self.displacement_step(V, factor, U_warm, mu_warm)
            U_warm, mu_warm = U, mu
            if jump_floor is not None:
                elastic = self._iterate_elastic(U, psi)
                if elastic < jump_floor:
                    raise CrackJumped(
                        f"the crack jumps at imposed-displacement factor {factor:.6g}: the "
                        f"elastic energy of staggered iterate {it} is {elastic:.6g}, below "
                        f"{jump_floor:.6g}.", elastic, it)
            step = self.phase.solve(psi, upper, V, hold_precracks=False)
            changes.append(float(np.abs(step.nodal - V).max()))
            V = step.nodal
            if changes[-1] < s.staggered_tol:
                break
        else:
            raise StaggeredNotConverged(
                f"the staggered solve did not converge at imposed-displacement factor "
                f"{factor:.6g}: max |Δυ| = {changes[-1]:.3g} after {s.max_staggered} "
                f"iterations (tolerance {s.staggered_tol:g}). Take smaller increments or raise "
                "physics.max_staggered.")
        return self._state(factor, U, V, mu, it, changes, negative, step.energy["fracture"],
                           started)

    def _iterate_elastic(self, U, psi):
        """The elastic energy of the displacement step's U at the degradation it was solved
        with: Σ_q w_q g_q ψ_q without a split (ψ the undegraded density, all of W), the
        assembled energy with one (ψ is then its tensile part only)."""
        if self.settings.split == "amor":
            return self.assembler_u.energy(U.ravel())["total"]
        return float(self.model.quadrature.weights @ (self.energy_u.degradation * psi))

    def _state(self, factor, U, V, mu, it, changes, negative, fracture, started,
               monolithic=0):
        """The FractureState of a converged increment (energies at the degradation of V,
        which the last displacement step set), logged with the wall time since ``started``
        (time.perf_counter() when the increment began)."""
        from pointatlas_solvers.increment import support_reactions

        elastic = self.assembler_u.energy(U.ravel())["total"]
        energy = {"elastic": elastic, "fracture": fracture,
                  "load_work": float(factor * self.F @ U.ravel())}
        reactions = support_reactions(self.constraints.matrix, mu,
                                      self.constraints.row_support, 3)
        if self.log is not None:
            self.log.info("factor %.6g: %s in %.2f s, elastic %.6g, fracture %.6g, min υ %.3f",
                          factor, f"monolithic Newton, {monolithic} iteration(s)" if monolithic
                          else f"{it} staggered iteration(s)",
                          time.perf_counter() - started, elastic, fracture,
                          float((self.interpolation @ V).min()))
            if negative:
                self.log.warning("factor %.6g: the displacement step's tangent has %d negative "
                                 "eigenvalue(s): u is not a minimum at the frozen phase field "
                                 "(kept in negative_modes)", factor, negative)
        return FractureState(float(factor), U, V, mu, it, energy, reactions, changes, negative,
                             monolithic)

    def with_split(self, split: str) -> "StaggeredProblem":
        """The same problem (surface model, supports, loads, pre-cracks) with the energy split
        ``split`` ('none' or 'amor'): a contrast run on the same atlas."""
        from dataclasses import replace

        from pointatlas.constraints import validate_parameters

        from .settings import FractureSettings

        s = replace(self.settings, split=split)
        validate_parameters(s, FractureSettings.parameter_constraints, prefix="physics")
        return StaggeredProblem(self.model, s, self.precrack_nodes, log=self.log)

    def away_from_precracks(self, initial_phase) -> np.ndarray:
        """(n,) bool: the points outside the pre-cracks' own bands, from υ₀ (n,) at the points
        in the initial state (no load; every point without pre-cracks). at2's band
        1 − υ₀ = exp(−d/2κ̄) never ends: outside it is where 1 − υ₀ < 0.05 (d ≳ 6κ̄ from a
        straight pre-crack); at1's band is compact, 1 − υ₀ = (1 − d/4κ̄)² for d < 4κ̄:
        outside it is where υ₀ = 1 (to :data:`INTACT`)."""
        v0 = np.asarray(initial_phase, dtype=np.float64)
        return v0 >= (1.0 - INTACT if self.settings.crack_model == "at1" else AWAY_AT2)

    def material(self) -> dict:
        """{young_modulus, poisson_ratio, thickness, fracture_toughness, length_scale,
        residual_stiffness}: the numbers a study's reference formulas need."""
        s = self.settings
        return {k: float(getattr(s, k)) for k in (
            "young_modulus", "poisson_ratio", "thickness", "fracture_toughness",
            "length_scale", "residual_stiffness")}

    def point_fields(self, state: FractureState):
        """(υ (n,), u (n, 3)) at the sampled points (the node basis evaluated once)."""
        if getattr(self, "_point_basis", None) is None:
            from pointatlas_atlas.evaluation import basis_at_nodes

            n = self.model.points.shape[0]
            basis, _, _ = basis_at_nodes(self.model.atlas, np.arange(n), order=0)
            self._point_basis = basis.to_csr(self.model.nodes.shape[0])
        B = self._point_basis
        return B @ state.phase_nodal, B @ state.displacement_nodal

    def restore_state(self, factor, U, V, mu, iterations, energy,
                      negative_modes: int = 0, monolithic_iterations: int = 0) -> FractureState:
        """A converged state from its saved arrays (a resumed path), reactions from μ."""
        from pointatlas_solvers.increment import support_reactions

        reactions = support_reactions(self.constraints.matrix, mu, self.constraints.row_support,
                                      3) if factor > 0 else None
        return FractureState(float(factor), np.asarray(U).reshape(-1, 3), np.asarray(V), mu,
                             int(iterations), dict(energy), reactions, [], int(negative_modes),
                            int(monolithic_iterations))

    def write_vtp(self, state: FractureState, path, magnification: float = 1.0,
                  field_data=None, units_system: str = "SI"):
        """The sampled points of ``state`` as a ParaView ``.vtp`` (:mod:`pointatlas_kit.
        paraview`, written atomically): the surface triangles (from the atlas's charts,
        computed once), point arrays ``phase_field`` υ (1), ``u`` (length), ``u_magnitude``
        |u| (length) and ``deformed`` = x + magnification·u (length), each with its
        ``NAME_units`` (in ``units_system``); field values ``load_factor`` t (1),
        ``magnification`` (1) and ``field_data`` (name → :class:`pointatlas_kit.paraview.
        Array`, e.g. ``TimeValue``)."""
        from pointatlas_kit.paraview import Array, write_vtp
        from pointatlas_kit.surface_mesh import surface_triangles

        if getattr(self, "_surface_triangles", None) is None:
            self._surface_triangles = surface_triangles(self.model.atlas,
                                                        self.model.points.shape[0])
        v, u = self.point_fields(state)
        x, m = self.model.points, float(magnification)
        return write_vtp(path, x, self._surface_triangles, {
            "phase_field": Array(v, "1", "phase field υ (1: intact, 0: broken)"),
            "u": Array(u, "length", "displacement u(x_a) at the sampled points"),
            "u_magnitude": Array(np.linalg.norm(u, axis=1), "length", "|u|"),
            "deformed": Array(x + m * u, "length", f"deformed position x_a + {m:g}·u")},
            {"load_factor": Array(float(state.factor), "1", "imposed-displacement factor t"),
             "magnification": Array(m, "1", "scale factor of u in 'deformed'"),
             **(field_data or {})}, units_system)

    def reaction(self, state: FractureState) -> float:
        """Σ over the imposed-displacement supports of their resultant force along the
        imposed direction (force): the force that pulls the boundary."""
        if state.reactions is None or not self.imposed:
            return 0.0
        total = 0.0
        for k, v in self.imposed:
            n = np.linalg.norm(v)
            if n > 0:
                total += float(state.reactions[k] @ (v / n))
        return total

    def imposed_displacement(self, factor: float) -> float:
        """|t v| of the first imposed-displacement support (length), 0 without one."""
        return float(factor * np.linalg.norm(self.imposed[0][1])) if self.imposed else 0.0
