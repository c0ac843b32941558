"""The phase-field step: min over υ of the crack energy at a fixed driving energy, irreversibly.

At fixed displacement the phase-field part of Π (:class:`.phase_field.CrackEnergy`) is a
quadratic ½ VᵀK_υV − F_υᵀV in the nodal values V (K_υ = the kit's tangent, F_υ = −R(0)),
minimised subject to

* the pre-cracks, υ(x_k) = Σ_b p_b(x_k) V_b = 0 at the points the selectors pick (C V = 0,
  augmented Lagrangian, :mod:`pointatlas_kit.supports`), imposed in the initial state, and
* irreversibility as the bound V ≤ V_prev on every nodal value (the previous increment's),
  and the range as V ≥ 0, both by projected Newton
  (:mod:`pointatlas_solvers.bound_constrained`).

Why V ≥ 0: the LME stiffness is not an M-matrix, so the discrete problem has no maximum
principle, and next to a fully broken band the nodal values overshoot below 0 (to −0.026 on
the 441-point Griffith quarter plate with a traction-free crack). g(υ) = υ² + η is even, so
the energy hardly notices, but υ < 0 is outside the model. The pre-crack rows are the
exception: Σ p_b(x_k) V_b = 0 with every V_b ≥ 0 would force V_b = 0 on the whole support of
every pre-crack point (several spacings wide, for a positive basis), so the nodes those rows
touch are free below in the initial state, and afterwards bounded below by min(0, V_prev).

After the initial state the pre-crack rows are implied: υ(x_k) = Σ p_b(x_k) V_b ≤
Σ p_b(x_k) V_prev,b = 0, so a pre-crack stays broken (υ ≤ 0 there) by irreversibility alone.
Holding the rows as equalities as well would make the multiplier iteration crawl (nearly all
nodes they touch sit at their bounds, leaving the rows almost no free unknowns); the results
report max |υ| at the pre-crack points of every increment (``precrack_violation``).

Why the bound and not Miehe's history field: the bound is the constraint of the variational
model itself (Bourdin–Francfort–Marigo: υ minimises Π over υ ≤ υ_prev), so the energy
that is minimised is the one reported; the history field replaces ψ by its running maximum,
which changes the energy and, on a meshfree basis without a discrete maximum principle, does
not by itself keep υ from rising anywhere. The LME basis is positive with Σ p_b = 1 (thesis
§3), so V_b ≤ V_prev,b for every node gives υ(x) = Σ p_b(x) V_b ≤ υ_prev(x) at *every*
point of the surface, exactly (IEEE rounding is monotone), not only at the nodes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pointatlas.errors import InputError


#: ghost springs of the phase field, relative to mean diag K (the shell's 1e-10 leaves far
#: ghost DOFs pivots below PARDISO's perturbation threshold once bounds fix their neighbours).
#: They pull toward the intact value υ = 1 (½ s (V − 1)²), so that an unloaded, uncracked
#: shell has υ ≡ 1 exactly; pulled toward 0 they lowered υ at boundary points of an intact
#: plate (to 0.9989 at a corner of the 441-point quarter plate, ghost values 0.08)
GHOST_SPRING = 1e-6
#: augmented-Lagrangian penalty of the pre-crack rows, relative to mean diag K: the scalar
#: phase-field system stays well conditioned at 10⁴, and each multiplier update then cuts
#: the violation about 10⁴-fold (each update is a bound-constrained solve)
PRECRACK_PENALTY = 1e4


@dataclass
class PhaseStep:
    """The result of one phase-field step."""

    nodal: np.ndarray          # (n_nodes,) V
    energy: dict               # {'fracture', 'degraded_elastic', 'total'} (energy units)
    active: np.ndarray         # (n_nodes,) bool: bounds held (V = V_prev)
    iterations: int            # projected-Newton iterations
    violation: float           # max |C V| at the pre-crack points


class PhaseProblem:
    """The assembled phase-field problem of a built surface model (see module doc)."""

    def __init__(self, model, settings, precrack_nodes):
        from pointatlas_kit.assembler import Assembler
        from pointatlas_kit.fields import FieldLayout
        from pointatlas_kit.supports import value_constraints

        from .phase_field import CrackEnergy

        self.model, self.settings = model, settings
        self.layout = FieldLayout(CrackEnergy.fields, model.nodes.shape[0])
        self.energy = CrackEnergy(settings.fracture_toughness, settings.thickness,
                                  settings.length_scale, settings.residual_stiffness,
                                  model=settings.crack_model)
        self.assembler = Assembler(model.quadrature, self.layout, [self.energy])
        if len(precrack_nodes):
            self.C, self.g = value_constraints(model.atlas, self.layout, "phase_field",
                                               precrack_nodes, 0.0)
        else:
            from scipy.sparse import csr_matrix

            self.C, self.g = csr_matrix((0, self.layout.n_dofs)), np.zeros(0)
        self.precrack_nodes = np.asarray(precrack_nodes, np.int64)
        from pointatlas_kit.surface_model import ghost_springs

        # weak ghost springs scaled by the intact problem (ψ = 0): fixed, so that a resumed
        # path solves the same systems as an uninterrupted one
        K0 = self.assembler.tangent(np.zeros(self.layout.n_dofs))
        self._springs = ghost_springs(K0.diagonal(), model, 1, GHOST_SPRING)

    def solve(self, driving, upper, start=None, hold_precracks: bool = True) -> PhaseStep:
        """Minimise at driving energy density ``driving`` (m,) (None: 0) with 0 ≤ V ≤ ``upper``,
        holding the pre-crack rows as equalities if ``hold_precracks`` (module doc)."""
        from scipy.sparse import csr_matrix

        from scipy.sparse import diags

        from pointatlas_solvers.bound_constrained import solve_bounded

        s = self.settings
        self.energy.driving = driving
        self.assembler.refresh_data()
        zero = np.zeros(self.layout.n_dofs)
        _, R0 = self.assembler.residual(zero)
        K = self.assembler.tangent(zero)
        K = (K + diags(self._springs)).tocsr()
        C, g = (self.C, self.g) if hold_precracks else (csr_matrix((0, K.shape[0])), np.zeros(0))
        lower = lower_bound(upper)
        if C.shape[0]:
            lower[np.unique(C.tocsr().indices)] = -np.inf
        V, info = solve_bounded(K, self._springs - R0, C, g, upper, penalty=PRECRACK_PENALTY,
                                tol=s.constraint_tol, backend=s.solver, start=start,
                                lower=lower)
        if not np.all(np.isfinite(V)):
            raise InputError("the phase-field solve produced NaN/inf: check the material "
                             "parameters and the pre-crack selectors.")
        return PhaseStep(V, self.assembler.energy(V), V == np.asarray(upper), info.iterations,
                         float(np.abs(self.C @ V - self.g).max(initial=0.0)))


def lower_bound(upper: np.ndarray) -> np.ndarray:
    """The nodal lower bound min(0, V_prev) of υ (module doc: V ≥ 0, except below nodal
    values a pre-crack already left negative)."""
    return np.minimum(0.0, np.asarray(upper, dtype=np.float64))


def precrack_nodes(points, selectors) -> np.ndarray:
    """Sorted point indices the pre-crack selectors pick (each must pick some), from the
    points alone (before any atlas work); InputError names an empty one."""
    from pointatlas_kit.selectors import select

    if not selectors:
        return np.zeros(0, np.int64)
    picked = []
    boundary = np.zeros(len(points), bool)
    for sel in selectors:
        if sel.on_boundary or sel.nearest_curve is not None:
            from pointatlas.errors import ConfigError

            raise ConfigError(f"{sel.name}: a pre-crack is selected among all points "
                              "(on_boundary: false, no nearest_curve); for an edge crack give a "
                              "polyline or a box that reaches the edge.")
        picked.append(select(sel, points, boundary, []))
    return np.unique(np.concatenate(picked))
