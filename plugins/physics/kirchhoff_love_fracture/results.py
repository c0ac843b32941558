"""A solved fracture problem as an xarray Dataset (dims ``point``, ``dim``)."""
from __future__ import annotations

import numpy as np

LENGTH = "length"
ONE = {"units": "1"}


def crack_length(fracture_energy: float, settings) -> float:
    """The crack length as the fracture energy divided by G_c h (length): exact for a fully
    developed straight band (:mod:`.phase_field`), an estimate while a crack forms."""
    return float(fracture_energy) / (settings.fracture_toughness * settings.thickness)


def phase_dataset(model, settings, step, phase):
    """Phase field at the points, energies, crack length and sizes of a phase-field solve."""
    import xarray as xr

    from pointatlas_kit.surface_model import values_at_nodes

    n = model.points.shape[0]
    v = values_at_nodes(model.atlas, step.nodal.reshape(-1, 1), np.arange(n))[:, 0]
    Gf = float(step.energy["fracture"])
    data = {
        "position": (("point", "dim"), model.points, {"long_name": "sampled point x_a",
                                                      "units": LENGTH}),
        "phase_field": (("point",), v, {**ONE, "long_name": "phase field υ(x_a) (1 intact, "
                                                            "0 broken)"}),
        "fracture_energy": ((), Gf, {"long_name": "crack energy G_c h ∫ (1−υ)²/(4κ̄) + "
                                                  "κ̄|∇υ|² dΩ", "units": "energy"}),
        "crack_length": ((), crack_length(Gf, settings), {
            "long_name": "crack length as fracture energy / (G_c h)", "units": LENGTH}),
        "fracture_toughness": ((), float(settings.fracture_toughness), {
            "long_name": "G_c", "units": "energy / length^2"}),
        "thickness": ((), float(settings.thickness), {"long_name": "shell thickness h",
                                                      "units": LENGTH}),
        "length_scale": ((), float(settings.length_scale), {
            "long_name": "phase-field length scale κ̄ (AT2 ℓ = 2κ̄)", "units": LENGTH}),
        "min_phase_field": ((), float(v.min()), {**ONE, "long_name": "min υ at the points"}),
        "max_phase_field": ((), float(v.max()), {**ONE, "long_name": "max υ at the points"}),
        "n_precrack_points": ((), len(phase.precrack_nodes), {
            **ONE, "long_name": "points held at υ = 0 by the pre-crack selectors"}),
        "precrack_violation": ((), float(step.violation), {
            **ONE, "long_name": "max |υ| at the pre-crack points"}),
        "active_bounds": ((), int(step.active.sum()), {
            **ONE, "long_name": "nodal values held at their irreversibility bound"}),
        "dof": ((), phase.layout.n_dofs, {**ONE, "long_name": "phase-field degrees of "
                                                              "freedom (ghosts included)"}),
        "n_points": ((), n, {**ONE, "long_name": "sampled points"}),
        "n_patches": ((), len(model.atlas.charts_), {**ONE, "long_name": "patches (charts)"}),
        **{f"time_{k}": ((), float(t), {"long_name": f"wall time of stage '{k}'", "units": "s"})
           for k, t in model.times.items()},
    }
    return xr.Dataset(data, coords={
        "point": ("point", np.arange(n), {"long_name": "point index", "units": "1"}),
        "dim": ("dim", ["x", "y", "z"], {"long_name": "Cartesian component", "units": "1"})})


def point_values(model, nodal) -> np.ndarray:
    """Field values at the sampled points from nodal values (n_nodes,) or (n_nodes, c)."""
    from pointatlas_kit.surface_model import values_at_nodes

    nodal = np.asarray(nodal)
    v = values_at_nodes(model.atlas, nodal.reshape(nodal.shape[0], -1),
                        np.arange(model.points.shape[0]))
    return v[:, 0] if nodal.ndim == 1 else v


def state_dataset(problem, state):
    """Displacement, phase field, energies and reaction of one converged increment."""
    import xarray as xr

    m = problem.model
    n = m.points.shape[0]
    v = point_values(m, state.phase_nodal)
    data = {
        "position": (("point", "dim"), m.points, {"long_name": "sampled point x_a",
                                                  "units": LENGTH}),
        "displacement": (("point", "dim"), point_values(m, state.displacement_nodal), {
            "long_name": "displacement u(x_a)", "units": LENGTH}),
        "phase_field": (("point",), v, {**ONE, "long_name": "phase field υ(x_a) (1 intact, "
                                                            "0 broken)"}),
        "elastic_energy": ((), state.energy["elastic"], {
            "long_name": "degraded strain energy ∫ (υ² + η) W(u)", "units": "energy"}),
        "fracture_energy": ((), state.energy["fracture"], {
            "long_name": "crack energy G_c h ∫ (1−υ)²/(4κ̄) + κ̄|∇υ|²", "units": "energy"}),
        "crack_length": ((), crack_length(state.energy["fracture"], problem.settings), {
            "long_name": "crack length as fracture energy / (G_c h)", "units": LENGTH}),
        "reaction": ((), problem.reaction(state), {
            "long_name": "force of the imposed-displacement supports along their direction",
            "units": "force"}),
        "staggered_iterations": ((), state.staggered_iterations, {
            **ONE, "long_name": "staggered iterations of the increment"}),
        "min_phase_field": ((), float(v.min()), {**ONE, "long_name": "min υ at the points"}),
        "n_points": ((), n, {**ONE, "long_name": "sampled points"}),
    }
    return xr.Dataset(data, coords={
        "point": ("point", np.arange(n), {"long_name": "point index", "units": "1"}),
        "dim": ("dim", ["x", "y", "z"], {"long_name": "Cartesian component", "units": "1"})})
