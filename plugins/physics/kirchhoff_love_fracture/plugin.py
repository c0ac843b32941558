"""The ``kirchhoff_love_fracture`` physics plugin: phase-field brittle fracture of thin shells.

Thesis §4 "Ongoing research" and Amiri, Millán, Shen, Rabczuk & Arroyo, Theor. Appl. Fract.
Mech. 69 (2014) 102–109, written on the physics kit: the shell's energy
(:class:`pointatlas_physics.kirchhoff_love.shell_energy.ShellEnergy`, geometrically exact for
``kinematics: nonlinear``, its quadratic form for ``linear``) degraded by g(υ) = υ² + η_κ̄
(:mod:`.degraded_energy`), a second field υ with the regularised crack energy (:mod:`.phase_field`), irreversibility as a bound
(:mod:`.phase_solve`) and a staggered solve per imposed-displacement increment
(:mod:`.staggered`). Notation: G_c ``fracture_toughness``, κ̄ ``length_scale`` (AT2 ℓ = 2κ̄),
η_κ̄ ``residual_stiffness``.
"""
from __future__ import annotations

from dataclasses import fields
from typing import ClassVar

import numpy as np

from pointatlas.stores_config import stores_config

from pointatlas_physics.kirchhoff_love.displacement_field import DISPLACEMENT

from .phase_field import PHASE_FIELD
from .settings import FractureSettings, check_fracture_settings, check_length_scale, \
    precrack_selectors


@stores_config
class KirchhoffLoveFracture:
    """Phase-field fracture of a Kirchhoff–Love shell given by points (module doc).

    ``solve(ctx, cloud=..., atlas_settings=...)``: with ``kinematics: none`` the phase field
    alone (pre-cracks, no driving energy) and its crack energy; otherwise one staggered
    increment at imposed-displacement factor 1 from the intact shell (the displacement solve
    of the chosen kinematics and the phase field it drives). Load paths go through :meth:`fracture_path` (study ``fracture``).
    """

    Config = FractureSettings
    fields: ClassVar[tuple] = (DISPLACEMENT, PHASE_FIELD)
    description: ClassVar[str] = (
        "Phase-field brittle fracture of Kirchhoff–Love shells on the atlas: the shell energy "
        "degraded by υ² + η, AT2 (or AT1) crack energy, irreversible (thesis §4, Amiri et al. "
        "2014).")
    #: a small problem for pointatlas.testing.check_physics: the conformance patch ([0, 1]² ×
    #: [0, 0.35]) clamped on its boundary under a surface load, with a pre-crack across it
    conformance_case: ClassVar[dict] = {
        "kinematics": "linear", "length_scale": 0.15,
        "supports": [{"kind": "clamped", "where": {"box": [-1.0, -1.0, -1.0, 2.0, 2.0, 2.0]}}],
        "loads": [{"kind": "surface", "force": [0.0, 0.0, -1.0]}],
        "precracks": [{"box": [0.45, -1.0, -1.0, 0.55, 2.0, 2.0]}]}

    def settings(self) -> FractureSettings:
        return FractureSettings(**{f.name: getattr(self, f.name)
                                   for f in fields(FractureSettings)})

    def check_config(self) -> None:
        """The checks of :func:`.settings.check_fracture_settings`, at start-up."""
        self.checked_settings()

    def checked_settings(self) -> FractureSettings:
        from pointatlas_physics.kirchhoff_love.plugin import _as_settings

        s = self.settings()
        if s.kinematics != "none":
            s = _as_settings(s)
        check_fracture_settings(s)
        return s

    def energies(self, positions=None) -> list:
        """The coupled energy of both fields (:class:`.degraded_energy.PhaseFieldShellEnergy`:
        the geometrically exact shell energy degraded by υ² + η, plus the crack energy), the
        one the conformance suite checks; the staggered solve uses its two halves
        (:mod:`.staggered`). Needs ``length_scale``."""
        from pointatlas.errors import ConfigError
        from pointatlas_physics.kirchhoff_love.shell_energy import ShellEnergy

        from .degraded_energy import PhaseFieldShellEnergy
        from .phase_field import CrackEnergy

        if self.length_scale is None:
            raise ConfigError("physics.length_scale (κ̄) is not set: give the crack band width.")
        shell = ShellEnergy(self.young_modulus, self.poisson_ratio, self.thickness)
        crack = CrackEnergy(self.fracture_toughness, self.thickness, self.length_scale,
                            self.residual_stiffness, model=self.crack_model)
        return [PhaseFieldShellEnergy(shell, crack)]

    def discrete_energy(self, patch: dict):
        from pointatlas_kit.energy import DiscreteEnergy

        return DiscreteEnergy(self.fields, self.energies(), patch)

    # -- building and solving -------------------------------------------------------------
    def build(self, ctx, cloud, atlas_settings):
        """(settings, surface model, pre-crack point indices), refusing a bad κ̄ or an empty
        pre-crack selector before the atlas is built."""
        from scipy.spatial import cKDTree

        from pointatlas_kit.surface_model import atlas_factories, build_surface_model

        from .phase_solve import precrack_nodes

        s = self.checked_settings()
        P = cloud.points
        spacing = float(np.median(cKDTree(P).query(P, k=2)[0][:, 1]))
        check_length_scale(s.length_scale, spacing, cloud.name)
        nodes = precrack_nodes(P, precrack_selectors(s))
        if s.kinematics == "none":
            factories = atlas_factories(ctx, atlas_settings, physics="kirchhoff_love_fracture")
            order, block = 1, 1
        else:
            from pointatlas_physics.kirchhoff_love.plugin import KirchhoffLove

            factories = KirchhoffLove.factories(ctx, atlas_settings)
            order, block = 2, 3
        model = build_surface_model(cloud, atlas_settings, **factories, order=order,
                                    ghost_layers=s.ghost_layers, block=block, log=ctx.log)
        return s, model, nodes

    def solve(self, ctx, *, cloud, atlas_settings):
        """See the class doc; returns the fields at the points and the energies (Dataset)."""
        from .phase_solve import PhaseProblem
        from .results import phase_dataset

        s, model, nodes = self.build(ctx, cloud, atlas_settings)
        if s.kinematics != "none":
            from .staggered import StaggeredProblem

            from .results import state_dataset

            problem = StaggeredProblem(model, s, nodes, log=ctx.log)
            state = problem.increment(problem.initial_state(), 1.0)
            self.solution_ = (model, problem.phase, state.phase_nodal, state)
            return state_dataset(problem, state)
        phase = PhaseProblem(model, s, nodes)
        step = phase.solve(None, np.ones(phase.layout.n_dofs))
        if ctx is not None:
            ctx.log.info("phase field: %d DOF, %d pre-crack points, %d bounds active, "
                         "violation %.2e", phase.layout.n_dofs, len(nodes), int(step.active.sum()),
                         step.violation)
        self.solution_ = (model, phase, step.nodal, step)
        return phase_dataset(model, s, step, phase)

    def fracture_path(self, ctx, *, cloud, atlas_settings):
        """The built problem for a load path (:class:`.staggered.StaggeredProblem`, with
        ``initial_state``, ``increment``, ``reaction``, ``imposed_displacement`` and
        ``point_fields``): what study ``fracture`` asks of this physics."""
        from pointatlas.errors import ConfigError

        from .staggered import StaggeredProblem

        s, model, nodes = self.build(ctx, cloud, atlas_settings)
        if s.kinematics == "none":
            raise ConfigError("study=fracture follows a load path of the shell: set "
                              "physics.kinematics=linear or nonlinear (kinematics=none is the "
                              "phase field alone, for study=crack_band).")
        problem = StaggeredProblem(model, s, nodes, log=ctx.log)
        if not problem.imposed and not np.any(problem.F):
            raise ConfigError("study=fracture needs a load: a support of kind 'displacement' "
                              "(displacement control) or a load in physics.loads.")
        self.solution_ = None
        self.problem_ = problem
        return problem

    def evaluate(self, name: str, x):
        """(values (k, c), projected points (k, 3)) of ``phase_field`` (or ``displacement``
        after a mechanical solve) at the surface points nearest to ``x`` (k, 3)."""
        from pointatlas.errors import ConfigError, PointatlasError
        from pointatlas_kit.surface_model import values_at

        sol = getattr(self, "solution_", None)
        if sol is None:
            raise PointatlasError("kirchhoff_love_fracture is not solved yet: call solve first.")
        model, _, V, state = sol
        if name == "phase_field":
            return values_at(model.atlas, V.reshape(-1, 1), x)
        if name == "displacement" and hasattr(state, "displacement_nodal"):
            return values_at(model.atlas, state.displacement_nodal, x)
        raise ConfigError(f"kirchhoff_love_fracture has the fields 'phase_field' and "
                          f"'displacement' (after a mechanical solve), not {name!r}.")
