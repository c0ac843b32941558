"""A solved fracture problem as an xarray Dataset (dims ``point``, ``dim``)."""
from __future__ import annotations

import numpy as np

LENGTH = "length"
ONE = {"units": "1"}
CRACK_ENERGY = ("regularised crack energy G_c h ∫ a w(1−υ)/κ̄ + b κ̄|∇υ|² dΩ "
                "(at2: a = ¼, w = (1−υ)², b = 1; at1: a = 3/16, w = 1−υ, b = ¾)")


def crack_length(fracture_energy: float, settings) -> float:
    """The crack length as the fracture energy divided by G_c h (length): exact for a fully
    developed straight band (:mod:`.phase_field`), an estimate while a crack forms."""
    return float(fracture_energy) / (settings.fracture_toughness * settings.thickness)


def _point_dataset(points, phase, data: dict):
    """The Dataset of ``data`` plus the positions and the phase field at the points."""
    import xarray as xr

    n = points.shape[0]
    base = {
        "position": (("point", "dim"), points, {"long_name": "sampled point x_a",
                                                "units": LENGTH}),
        "phase_field": (("point",), phase, {**ONE, "long_name": "phase field υ(x_a) (1 intact, "
                                                                "0 broken)"}),
        "min_phase_field": ((), float(phase.min()), {**ONE, "long_name": "min υ at the points"}),
        "n_points": ((), n, {**ONE, "long_name": "sampled points"}),
    }
    return xr.Dataset({**base, **data}, coords={
        "point": ("point", np.arange(n), {"long_name": "point index", "units": "1"}),
        "dim": ("dim", ["x", "y", "z"], {"long_name": "Cartesian component", "units": "1"})})


def phase_dataset(model, settings, step, phase):
    """Phase field at the points, energies, crack length and sizes of a phase-field solve."""
    from pointatlas_kit.surface_model import values_at_nodes

    n = model.points.shape[0]
    v = values_at_nodes(model.atlas, step.nodal.reshape(-1, 1), np.arange(n))[:, 0]
    Gf = float(step.energy["fracture"])
    data = {
        "fracture_energy": ((), Gf, {"long_name": CRACK_ENERGY, "units": "energy"}),
        "crack_length": ((), crack_length(Gf, settings), {
            "long_name": "crack length as fracture energy / (G_c h)", "units": LENGTH}),
        "fracture_toughness": ((), float(settings.fracture_toughness), {
            "long_name": "G_c", "units": "energy / length^2"}),
        "thickness": ((), float(settings.thickness), {"long_name": "shell thickness h",
                                                      "units": LENGTH}),
        "length_scale": ((), float(settings.length_scale), {
            "long_name": "phase-field length scale κ̄ (ℓ = 2κ̄)", "units": LENGTH}),
        "crack_model": ((), str(settings.crack_model), {
            **ONE, "long_name": "crack energy model (at2: the thesis' quadratic, at1: "
                                "linear, with an elastic threshold)"}),
        "max_phase_field": ((), float(v.max()), {**ONE, "long_name": "max υ at the points"}),
        "n_precrack_points": ((), len(phase.precrack_nodes), {
            **ONE, "long_name": "points held at υ = 0 by the pre-crack selectors"}),
        "precrack_violation": ((), float(step.violation), {
            **ONE, "long_name": "max |υ| at the pre-crack points"}),
        "active_bounds": ((), int(step.active.sum()), {
            **ONE, "long_name": "nodal values held at their irreversibility bound"}),
        "dof": ((), phase.layout.n_dofs, {**ONE, "long_name": "phase-field degrees of "
                                                              "freedom (ghosts included)"}),
        "n_patches": ((), len(model.atlas.charts_), {**ONE, "long_name": "patches (charts)"}),
        **{f"time_{k}": ((), float(t), {"long_name": f"wall time of stage '{k}'", "units": "s"})
           for k, t in model.times.items()},
    }
    return _point_dataset(model.points, v, data)


def state_dataset(problem, state):
    """Displacement, phase field, energies and reaction of one converged increment (the
    fields through the problem's cached point basis)."""
    v, u = problem.point_fields(state)
    data = {
        "displacement": (("point", "dim"), u, {"long_name": "displacement u(x_a)",
                                               "units": LENGTH}),
        "elastic_energy": ((), state.energy["elastic"], {
            "long_name": "degraded strain energy ∫ (υ² + η) W(u)", "units": "energy"}),
        "fracture_energy": ((), state.energy["fracture"], {
            "long_name": CRACK_ENERGY, "units": "energy"}),
        "crack_length": ((), crack_length(state.energy["fracture"], problem.settings), {
            "long_name": "crack length as fracture energy / (G_c h)", "units": LENGTH}),
        "reaction": ((), problem.reaction(state), {
            "long_name": "force of the imposed-displacement supports along their direction",
            "units": "force"}),
        "staggered_iterations": ((), state.staggered_iterations, {
            **ONE, "long_name": "staggered iterations of the increment"}),
    }
    return _point_dataset(problem.model.points, v, data)
