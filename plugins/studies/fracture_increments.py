"""``increments.nc`` of a fracture path: every accepted increment, durable, resumable.

The same mechanism as the shell path's (:mod:`.increment_store`: the settings a path depends
on stored as ``resume_settings`` and checked on resume, an atomic write through
:func:`pointatlas.results.write_netcdf_atomic`), holding what the fracture path goes on from:
the nodal displacement U, phase field V and support multipliers μ of each increment, its
factor, energies and staggered iterations, and the step controller's current step. A resume
rebuilds the states from these and continues the same loop, so its results are those of the
run that was never stopped (the solves are deterministic).
"""
from __future__ import annotations

import json

import numpy as np

from pointatlas.errors import InputError
from pointatlas.results import write_netcdf_atomic

NAME = "increments.nc"
FORMAT = "fracture-1"
ONE = {"units": "1"}
ENERGY = {"units": "energy"}
#: a crack has nucleated (or grown) away from the pre-cracks where min υ drops below this
NUCLEATED = 0.1


def nucleation_displacement(delta, away_min) -> float:
    """The first imposed displacement at which ``away_min`` < :data:`NUCLEATED` (NaN if
    never): the increment that first shows the crack (no interpolation between increments;
    the step refinement at a crack jump sets its resolution)."""
    hit = np.flatnonzero(np.asarray(away_min) < NUCLEATED)
    return float(delta[hit[0]]) if hit.size else float("nan")


def dataset(problem, records):
    """The path Dataset along ``increment`` (the study's results; module doc of .fracture)."""
    import xarray as xr

    m = problem.model
    n = m.points.shape[0]
    t = np.array([r.factor for r in records])
    delta = np.array([problem.imposed_displacement(x) for x in t])
    reaction = np.array([problem.reaction(r) for r in records])
    work = np.concatenate([[0.0], np.cumsum(0.5 * (reaction[1:] + reaction[:-1])
                                            * np.diff(delta))])
    work += np.array([r.energy["load_work"] for r in records])
    s = problem.settings
    fields = [problem.point_fields(r) for r in records]
    phase = np.stack([f[0] for f in fields])
    # outside the pre-cracks' own bands (the physics knows its band); none away: NaN
    away = np.asarray(problem.away_from_precracks(phase[0]), dtype=bool)
    away_min = phase[:, away].min(axis=1) if away.any() else np.full(len(phase), np.nan)
    data = {
        "load_factor": (("increment",), t, {**ONE, "long_name": "imposed-displacement factor t"}),
        "imposed_displacement": (("increment",), delta, {
            "long_name": "|t v| of the first imposed-displacement support", "units": "length"}),
        "reaction": (("increment",), reaction, {
            "long_name": "force of the imposed-displacement supports along their direction",
            "units": "force"}),
        "elastic_energy": (("increment",), [r.energy["elastic"] for r in records], {
            **ENERGY, "long_name": "degraded strain energy ∫ (υ² + η) W(u)"}),
        "fracture_energy": (("increment",), [r.energy["fracture"] for r in records], {
            **ENERGY, "long_name": "regularised crack energy (at2: G_c h ∫ (1−υ)²/(4κ̄) + "
                                   "κ̄|∇υ|²; at1: G_c h ∫ 3(1−υ)/(16κ̄) + (3κ̄/4)|∇υ|²)"}),
        "external_work": (("increment",), work, {
            **ENERGY, "long_name": "∫ reaction d(imposed displacement) (trapezoidal) + t Fᵀu"}),
        "staggered_iterations": (("increment",), [r.staggered_iterations for r in records], {
            **ONE, "long_name": "staggered iterations of the increment"}),
        "monolithic_iterations": (("increment",), [r.monolithic_iterations for r in records], {
            **ONE, "long_name": "Newton iterations of the monolithic solve of the increment "
                                "(0: solved by the staggered scheme)"}),
        "negative_modes": (("increment",), [r.negative_modes for r in records], {
            **ONE, "long_name": "checked negative eigenvalues of the displacement step's "
                                "tangent (0: u minimises at the frozen phase field)"}),
        "crack_length": (("increment",), [r.energy["fracture"] / (s.fracture_toughness *
                                                                  s.thickness) for r in records],
                         {"long_name": "crack length as fracture energy / (G_c h)",
                          "units": "length"}),
        "min_phase_field_away": (("increment",), away_min, {
            **ONE, "long_name": "min υ at the points away from the pre-cracks (outside their "
                                "own bands at increment 0: away_from_precracks)"}),
        "away_from_precracks": (("point",), away.astype(np.int8), {
            **ONE, "long_name": "1 where the point is outside the pre-cracks' own bands at "
                                "increment 0 (at2: υ₀ ≥ 0.95; at1: υ₀ = 1, its band is "
                                "compact)"}),
        "nucleation_displacement": ((), nucleation_displacement(delta, away_min), {
            "units": "length", "long_name": f"imposed displacement at which min υ away from "
                                            f"the pre-cracks first drops below {NUCLEATED:g} "
                                            f"(NaN: not on this path)"}),
        "min_phase_field": ((), float(away_min[-1]), {
            **ONE, "long_name": "min υ away from the pre-cracks at the last increment"}),
        "phase_field": (("increment", "point"), phase, {
            **ONE, "long_name": "phase field υ(x_a) (1 intact, 0 broken)"}),
        "displacement": (("increment", "point", "dim"), np.stack(
            [f[1] for f in fields]), {
            "long_name": "displacement u(x_a)", "units": "length"}),
        "position": (("point", "dim"), m.points, {"long_name": "sampled point x_a",
                                                  "units": "length"}),
        "n_points": ((), n, {**ONE, "long_name": "sampled points"}),
        "n_increments_done": ((), len(records) - 1, {**ONE, "long_name": "accepted increments"}),
    }
    ds = xr.Dataset(data, coords={
        "increment": ("increment", np.arange(len(records)), {
            **ONE, "long_name": "increment (0: the initial state)"}),
        "point": ("point", np.arange(n), {**ONE, "long_name": "point index"}),
        "dim": ("dim", ["x", "y", "z"], {**ONE, "long_name": "Cartesian component"})})
    ds.attrs["split"] = s.split
    return ds


def write(path, problem, records, step: float, settings: dict) -> None:
    """increments.nc with the path Dataset and the states it goes on from (durably)."""
    ds = dataset(problem, records)
    ds["nodal_displacement"] = (("increment", "node", "dim"), np.stack(
        [r.displacement_nodal for r in records]), {"long_name": "nodal displacements U",
                                                    "units": "length"})
    ds["nodal_phase_field"] = (("increment", "node"), np.stack(
        [r.phase_nodal for r in records]), {**ONE, "long_name": "nodal phase field V"})
    ds["multipliers"] = (("increment", "constraint"), np.stack(
        [r.multipliers for r in records]), {"long_name": "support multipliers μ",
                                            "units": "force"})
    ds["energy_load_work"] = (("increment",), [r.energy["load_work"] for r in records], {
        **ENERGY, "long_name": "t Fᵀu of the dead loads"})
    ds["controller_step"] = ((), float(step), {**ONE, "long_name": "the step controller's "
                                                             "next step (fraction of max)"})
    ds.attrs.update(resume_settings=json.dumps(settings, sort_keys=True),
                    increments_format=FORMAT)
    write_netcdf_atomic(ds, path)


def read(run_dir, settings: dict):
    """The Dataset of ``run_dir``/increments.nc after checking it is a fracture path's and
    was computed with ``settings`` (InputError / ConfigError naming the fix)."""
    from .increment_store import check_settings, load_increments_file

    path, old = load_increments_file(run_dir)
    if old.attrs.get("increments_format") != FORMAT or "resume_settings" not in old.attrs:
        raise InputError(f"study.resume_from={run_dir}: {path} is not the increments file of "
                         "a fracture path; give the run directory of an interrupted "
                         "study=fracture run, or rerun without study.resume_from.")
    check_settings(path, json.loads(old.attrs["resume_settings"]), settings)
    return old


def restore(old, problem, run_dir):
    """(states, step) from a read increments Dataset, checked against the built problem."""
    n_nodes = problem.model.nodes.shape[0]
    if old.sizes.get("node") != n_nodes or \
            old.sizes.get("constraint") != problem.constraints.matrix.shape[0]:
        raise InputError(f"study.resume_from={run_dir}: its increments hold {old.sizes.get('node')}"
                         f" nodes, this run builds {n_nodes}: resume with the same source and "
                         "settings, or rerun without study.resume_from.")
    states = []
    for k in range(old.sizes["increment"]):
        states.append(problem.restore_state(
            float(old["load_factor"].values[k]), old["nodal_displacement"].values[k].copy(),
            old["nodal_phase_field"].values[k].copy(), old["multipliers"].values[k].copy(),
            int(old["staggered_iterations"].values[k]),
            {"elastic": float(old["elastic_energy"].values[k]),
             "fracture": float(old["fracture_energy"].values[k]),
             "load_work": float(old["energy_load_work"].values[k])},
            *(int(old[v].values[k]) if v in old else 0
              for v in ("negative_modes", "monolithic_iterations"))))
    return states, float(old["controller_step"])
