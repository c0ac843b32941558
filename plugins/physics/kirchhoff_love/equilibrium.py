"""The equilibrium equations of a loaded, supported nonlinear shell at a load factor λ.

Thesis §4.4, App. E.2 (L3669–3700) and Paper 2 App. E: with the geometrically exact energy W
(:mod:`.nonlinear`), external loads λF and supports CU = λg (loads and imposed displacements
are both scaled by λ), the augmented Lagrangian of the total potential is

    Π_ρ(U; μ, λ) = W(U) − λFᵀU + μᵀ(CU − λg) + ½ρ|CU − λg|²,

whose gradient at ρ-feasible points is the out-of-balance force R = f_int(U) − λF + Cᵀμ.
:class:`Equilibrium` evaluates R and Π_ρ (one numba pass gives both), factorises the
constrained tangent K_T + ρCᵀC (the solvers' :class:`ConstrainedSystem`, whose pivot signs flag
unstable equilibria), and runs the coarse L-BFGS stage that precedes Newton (thesis L2301:
"we first obtain a coarse and robust approximation of the equilibrium point with a
limited-memory BFGS method and then switch to Newton's method combined with line search").
It is the shell's :class:`pointatlas_solvers.equilibrium_problem.EquilibriumProblem`.
"""
from __future__ import annotations

import numpy as np


class Equilibrium:
    """R(U, μ, λ), Π_ρ(U; μ, λ), the constrained tangent and the L-BFGS stage of one shell."""

    def __init__(self, model, settings, F: np.ndarray, constraints, assembler=None):
        """``assembler``: the kit assembler of the strain energy W (default: the shell's
        geometrically exact energy on ``model.quadrature``); another energy of the same
        displacement field, e.g. the shell's degraded by a frozen phase field (the
        displacement step of ``kirchhoff_love_fracture``), keeps the rest as it is."""
        self.model, self.settings = model, settings
        self.q, self.mat = model.quadrature, model.material
        self.C, self.g = constraints.matrix, constraints.rhs
        self.F = np.asarray(F, dtype=float).ravel()
        self.constraints = constraints
        self.rho = None   # set by the first factorisation (scale free, from diag K)
        self._last_system = None   # handed on to the next system() (reuse)
        # what the path followers ask of the problem (pointatlas_solvers.equilibrium_problem)
        n_nodes, n_real = model.nodes.shape[0], model.points.shape[0]
        self.n_components, self.row_support = 3, constraints.row_support
        self.length_scale = float(np.ptp(model.nodes, axis=0).max())
        # the arc length is measured on the sampled points' DOFs (ghosts nearly free)
        self.arc_mask = np.repeat(np.arange(n_nodes) < n_real, 3).astype(float)
        # the weak ghost springs of the linear analysis, frozen and part of the energy
        # (½ sᵀU², force sU), so that Newton's fixed point and its tangent agree and the
        # nearly free far ghost DOFs do not drift from one iteration to the next
        from pointatlas_kit.surface_model import ghost_springs

        from .nonlinear import shell_assembler

        self.assembler = assembler if assembler is not None else \
            shell_assembler(self.q, self.mat)                 # the kit's, pattern cached
        K0 = self.assembler.tangent(np.zeros(self.assembler.layout.n_dofs))
        self.springs = ghost_springs(K0.diagonal(), model, 3)

    def energy_and_forces(self, U: np.ndarray):
        """(W, f_int): strain energy (energy) and internal forces (force), one kernel pass."""
        W, f = self.assembler.residual(U)
        U = U.ravel()
        return W + 0.5 * float(self.springs @ (U * U)), f + self.springs * U

    def energy_parts(self, U) -> dict:
        """{'total', 'membrane', 'bending'} strain energy at U (energy)."""
        return self.assembler.energy(U)

    def residual(self, U, mu, lam):
        """(R, W): out-of-balance force f_int(U) − λF + Cᵀμ and the strain energy."""
        W, f = self.energy_and_forces(U)
        return f - lam * self.F + self.C.T @ mu, W

    def scale(self, lam, mu) -> float:
        """Force scale of the residual: the applied load, or the reactions when F = 0."""
        return max(float(np.linalg.norm(lam * self.F)), float(np.linalg.norm(self.C.T @ mu)),
                   1e-300)

    def merit(self, W, U, mu, lam) -> float:
        """Π_ρ(U; μ, λ) given W = W(U) (energy)."""
        c = self.C @ U - lam * self.g
        return W - lam * float(self.F @ U) + float(mu @ c) + 0.5 * (self.rho or 0.0) * float(c @ c)

    def system(self, U, shift: float = 0.0):
        """The factorised constrained tangent K_T(U) + ρCᵀC (:class:`ConstrainedSystem`);
        ``shift`` σ (force per length) adds σI, a modified Newton step that descends on an
        indefinite K_T (:mod:`pointatlas_solvers.stable_equilibrium`). The system of the
        previous call is handed on (``reuse``, as the protocol allows): every tangent has
        the same sparsity pattern, so PARDISO factorises without a new analysis (pull-out,
        5 250 DOF: 0.45 s against 0.64 s, the same factors bit for bit)."""
        from scipy.sparse import diags

        from pointatlas_solvers.augmented_lagrangian import ConstrainedSystem

        K = (self.assembler.tangent(U)
             + diags(self.springs + shift)).tocsr()
        sys = ConstrainedSystem(K, self.C, self.settings.penalty, self.settings.constraint_tol,
                                backend=self.settings.solver,
                                reuse=self._last_system)
        self._last_system = sys
        self.rho = sys.rho
        return sys

    def lbfgs(self, U, mu, lam, rel_tol: float, max_iter: int, log=None):
        """Coarse minimisation of Π_ρ(·; μ, λ) by L-BFGS from U, to a gradient of rel_tol
        times the load scale (the robust first stage of App. E.2). Returns (U, iterations)."""
        from scipy.optimize import minimize

        if self.rho is None or max_iter <= 0:
            return U, 0
        rho, C, g = self.rho, self.C, self.g

        def fun(x):
            W, f = self.energy_and_forces(x)
            c = C @ x - lam * g
            grad = f - lam * self.F + C.T @ (mu + rho * c)
            return self.merit(W, x, mu, lam), grad

        scale = self.scale(lam, mu)
        start = fun(U)[0]
        res = minimize(fun, U, jac=True, method="L-BFGS-B",
                       options={"maxiter": max_iter, "gtol": rel_tol * scale / np.sqrt(U.size),
                                "maxcor": 20})
        if not np.all(np.isfinite(res.x)) or not res.fun <= start:
            return U, int(res.nit)
        if log is not None:
            log.info("  λ = %.5g  L-BFGS: %d iterations, |∇Π| = %.3e", lam, res.nit,
                     float(np.linalg.norm(res.jac)) / scale)
        return res.x, int(res.nit)
