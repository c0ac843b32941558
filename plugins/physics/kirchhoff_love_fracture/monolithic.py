"""Monolithic Newton for one increment: both fields at once, with the full coupled tangent.

The staggered solve (:mod:`.staggered`) alternates the two minimisations; here (U, V) move
together. The coupled energy per area is :class:`.degraded_energy.PhaseFieldShellEnergy`,

    W(u, υ) = (υ² + η) W_shell(u) + G_c h [(1 − υ)²/(4κ̄) + κ̄ |∇υ|²],

(W_shell the shell's linearised or geometrically exact energy), assembled by the kit on the
two-field layout (node block (u₁, u₂, u₃, υ)); its Hessian holds ∂²W/∂u∂υ = 2υ ∂W_shell/∂u.
Each iteration is a projected Newton step (Bertsekas, SIAM J. Control Optim. 20 (1982) 221):
with R = ∂Π/∂X, the bounds held are 𝒜 = {V_i ≥ V_prev,i − ε, R_Vi < 0} (irreversibility) ∪
{V_i ≤ l_i + ε, R_Vi > 0} (υ ≥ 0: l = :func:`.phase_solve.lower_bound`); on the free
unknowns (all of U and V off 𝒜) the step minimises the quadratic model subject to the
supports C U = t g (augmented Lagrangian, the shared :class:`ConstrainedSystem`), then V is
projected onto l ≤ V ≤ V_prev and the step is backtracked (Armijo on Π) once U is feasible.

*Where it converges.* The AT2 energy is convex in u and in υ separately, not jointly: past
the onset of softening the coupled tangent on the free set is indefinite and a Newton step
heads for a saddle. The step is taken only while the factorised tangent has no negative
pivot (its inertia, Sylvester); otherwise, or when no descent is found or the iteration cap
``max_newton`` is reached, :class:`MonolithicNotConverged` is raised and the increment is
solved by the staggered scheme from the same state (the study records which did it).
Converged: the supports' residual below ``newton_tol`` of the force scale, the active set
unchanged, and the last step below 1e-3 ``staggered_tol`` (at least :data:`V_STEP`) in V
(dimensionless) and :data:`U_STEP` of max |U| in U.
"""
from __future__ import annotations

import numpy as np

from .phase_solve import lower_bound
from .staggered import StaggeredNotConverged

#: Armijo constant and the smallest backtracking factor of a step
ARMIJO, MIN_STEP = 1e-4, 1e-6
#: a step whose predicted change of Π is below this fraction of |Π| is taken in full: the
#: Armijo test cannot see it through the round-off (on the 1 681-point Griffith plate every
#: elastic increment stalled there, "no descent", after 12-22 iterations, without this)
ROUND_OFF = 1e-12
#: the last U step, relative to max |U|, below which U is converged (with the residual): the
#: steps stall at 1-3e-8 on that plate, the floor the constraint solve's tolerance leaves,
#: while the residual is at 1e-10 of the reactions; 1e-8 there never converged
U_STEP = 1e-6
#: floor of the V step test (dimensionless): the steps stall at 1-3e-10 (round-off)
V_STEP = 1e-9


class MonolithicNotConverged(StaggeredNotConverged):
    """The monolithic Newton iteration gave up (the staggered scheme takes over)."""


class MonolithicNewton:
    """The coupled problem of a :class:`.staggered.StaggeredProblem` (its model, supports,
    loads, springs and phase-field springs), solved increment by increment."""

    def __init__(self, problem):
        from scipy.sparse import csr_matrix

        from pointatlas_kit.assembler import Assembler
        from pointatlas_kit.fields import FieldLayout
        from pointatlas_physics.kirchhoff_love.shell_energy import ShellEnergy

        from .degraded_energy import Linearized, PhaseFieldShellEnergy
        from .phase_field import PHASE_FIELD, CrackEnergy

        s = problem.settings
        self.problem, self.settings = problem, s
        base = ShellEnergy(s.young_modulus, s.poisson_ratio, s.thickness)
        shell = base if s.kinematics == "nonlinear" else Linearized(base)
        crack = CrackEnergy(s.fracture_toughness, s.thickness, s.length_scale,
                            s.residual_stiffness, model=s.crack_model)
        n = problem.model.nodes.shape[0]
        self.layout = FieldLayout((*base.fields, PHASE_FIELD), n)
        self.assembler = Assembler(problem.model.quadrature, self.layout,
                                   [PhaseFieldShellEnergy(shell, crack)])
        self.u = self.layout.dofs(base.fields[0].name, np.arange(n)).ravel()   # 4a + i
        self.v = self.layout.dofs("phase_field", np.arange(n)).ravel()         # 4a + 3
        N = self.layout.n_dofs
        self.springs = np.zeros(N)
        self.springs[self.u] = problem.springs.diagonal()
        self.springs[self.v] = problem.phase._springs
        self.reference = np.zeros(N)            # springs pull u to 0 and υ to 1 (intact)
        self.reference[self.v] = 1.0
        self.F = np.zeros(N)
        self.F[self.u] = problem.F
        C = problem.constraints.matrix.tocoo()  # rows on the shell's 3a + i numbering
        self.C = csr_matrix((C.data, (C.row, self.u[C.col])), shape=(C.shape[0], N))
        self.g = problem.constraints.rhs

    def _energy(self, X, factor):
        W, f = self.assembler.residual(X)
        d = X - self.reference
        return (W + 0.5 * float(self.springs @ (d * d)) - factor * float(self.F @ X),
                f + self.springs * d - factor * self.F)

    def solve(self, state, factor: float):
        """(U (n, 3), V (n,), μ, iterations) at ``factor`` from the converged ``state``
        (module doc); :class:`MonolithicNotConverged` when it gives up."""
        from scipy.sparse import diags

        from pointatlas_solvers.augmented_lagrangian import ConstrainedSystem

        s, N = self.settings, self.layout.n_dofs
        upper = state.phase_nodal
        lower = lower_bound(upper)
        X = np.empty(N)
        X[self.u], X[self.v] = state.displacement_nodal.ravel(), upper
        feasible, active_before = False, None
        Pi, R = self._energy(X, factor)
        for it in range(1, s.max_newton + 1):
            V = X[self.v]
            eps = min(1e-9, float(np.abs(V - np.clip(V - R[self.v], lower, upper)).max()))
            held = (V >= upper - eps) & (R[self.v] < 0)
            floor = (V <= lower + eps) & (R[self.v] > 0) & ~held
            free = np.ones(N, bool)
            free[self.v[held | floor]] = False
            X[self.v[held]] = upper[held]
            X[self.v[floor]] = lower[floor]
            f = np.flatnonzero(free)
            K = (self.assembler.tangent(X) + diags(self.springs)).tocsr()[f][:, f]
            system = ConstrainedSystem(K, self.C[:, f], s.penalty, s.constraint_tol,
                                       backend=s.solver)
            if system.negative_pivots != 0:
                why = ("has negative pivots" if system.negative_pivots > 0 else
                       "gives no inertia with this backend")
                raise MonolithicNotConverged(
                    f"monolithic Newton at factor {factor:.6g}: the coupled tangent {why} "
                    f"(iteration {it}): not a descent method here")
            Xf, mu, _ = system.solve(K @ X[f] - R[f], factor * self.g)
            d = np.zeros(N)
            d[f] = Xf - X[f]
            alpha = 1.0
            while True:
                Xn = X + alpha * d
                Xn[self.v] = np.clip(Xn[self.v], lower, upper)
                Pn, Rn = self._energy(Xn, factor)
                slope = float(R @ (Xn - X))
                # the change Newton predicts is below the round-off of Π: nothing to test
                # (near the minimiser Π(X + d) − Π(X) is all cancellation)
                lost = abs(slope) <= ROUND_OFF * max(abs(Pi), abs(Pn), 1e-300)
                if not feasible or lost or Pn <= Pi + ARMIJO * slope:
                    break
                alpha *= 0.5
                if alpha < MIN_STEP:
                    raise MonolithicNotConverged(f"monolithic Newton at factor {factor:.6g}: "
                                                 f"no descent along the step (iteration {it})")
            step = Xn - X
            X, Pi, R, feasible = Xn, Pn, Rn, True
            RU = R[self.u] + (self.C.T @ mu)[self.u]
            scale = max(float(np.linalg.norm(factor * self.F)),
                        float(np.linalg.norm(self.C.T @ mu)), 1e-300)
            u_max = max(np.abs(X[self.u]).max(), 1e-300)
            small_u = np.abs(step[self.u]).max() <= U_STEP * u_max
            small_v = np.abs(step[self.v]).max() <= max(1e-3 * s.staggered_tol, V_STEP)
            bound = held | floor
            same = active_before is not None and np.array_equal(bound, active_before)
            active_before = bound
            if np.linalg.norm(RU) <= s.newton_tol * scale and small_u and small_v and same:
                return X[self.u].reshape(-1, 3), X[self.v].copy(), mu, it
        raise MonolithicNotConverged(f"monolithic Newton did not converge at factor "
                                     f"{factor:.6g} in {s.max_newton} iterations")
