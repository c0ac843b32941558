"""A trajectory of the body as an xarray Dataset (dims ``time``, ``node``, ``dim``, ``face``).

Units are consistent ones named ``length``, ``time``, ``mass``; the plane-strain body is per
unit thickness, so energies are ``energy / length`` (= force) and nodal masses
``mass / length``. The mesh follows UGRID: a ``mesh_topology`` variable pointing at the node
coordinates ``node_x``/``node_y`` (reference positions) and ``face_node_connectivity``
(0-based, counter-clockwise).
"""
from __future__ import annotations

import numpy as np

L, V, E = "length", "length / time", "energy / length"
ONE = {"units": "1"}


def trajectory_dataset(body, traj, mass_kind: str, dt: float):
    """Dataset of :class:`~.integrator.Trajectory` ``traj`` of :class:`~.body.ElasticBody`
    ``body`` (``mass_kind`` the mass matrix used, ``dt`` the time step)."""
    import xarray as xr

    X = body.reference
    tri = body.mesh.triangles
    ds = xr.Dataset(coords={
        "time": ("time", traj.time, {"long_name": "time of the saved step", "units": "time"}),
        "step": ("time", traj.step, {"long_name": "time step index", **ONE}),
        "node": ("node", np.arange(len(X)), {"long_name": "mesh node", **ONE}),
        "dim": ("dim", ["x", "y"], {"long_name": "Cartesian component", **ONE}),
        "face": ("face", np.arange(len(tri)), {"long_name": "triangle of the mesh", **ONE}),
        "corner": ("corner", np.arange(3), {"long_name": "corner of a triangle", **ONE}),
        "node_x": ("node", X[:, 0], {"long_name": "reference x of the node",
                                     "standard_name": "projection_x_coordinate", "units": L}),
        "node_y": ("node", X[:, 1], {"long_name": "reference y of the node",
                                     "standard_name": "projection_y_coordinate", "units": L})})
    ds["mesh_topology"] = ((), np.int32(0), {
        "long_name": "UGRID topology of the reference mesh", "cf_role": "mesh_topology",
        "topology_dimension": 2, "node_coordinates": "node_x node_y",
        "face_node_connectivity": "face_node_connectivity", **ONE})
    ds["face_node_connectivity"] = (("face", "corner"), tri.astype(np.int64), {
        "long_name": "nodes of each triangle, counter-clockwise", "cf_role":
        "face_node_connectivity", "start_index": 0, **ONE})
    ds["clamped"] = (("node",), body.clamped.astype(np.int8), {
        "long_name": "1 where the node is clamped (both components fixed)", **ONE})
    ds["nodal_mass"] = (("node",), body.nodal_masses, {
        "long_name": "lumped nodal mass ∫ ρ N_a dA", "units": "mass / length"})
    ds["position"] = (("time", "node", "dim"), traj.x, {
        "long_name": "current position x of the node", "units": L})
    ds["displacement"] = (("time", "node", "dim"), traj.x - X[None], {
        "long_name": "displacement x − X", "units": L})
    ds["velocity"] = (("time", "node", "dim"), traj.v, {
        "long_name": "velocity of the node", "units": V})
    for name, values, long in (
            ("kinetic_energy", traj.kinetic, "kinetic energy ½ vᵀ M v"),
            ("elastic_energy", traj.elastic, "neo-Hookean strain energy Σ A_e W(F_e)"),
            ("gravity_energy", traj.gravity, "potential of gravity −f_extᵀ (x − X)"),
            ("potential_energy", traj.elastic + traj.gravity,
             "potential energy V = elastic + gravity"),
            ("total_energy", traj.total, "total energy T + V")):
        ds[name] = (("time",), values, {"long_name": f"{long} per unit thickness", "units": E})
    drift = np.abs(traj.total - traj.total[0])
    scale = float(traj.kinetic.max())
    scalars = {
        "dt": (dt, "time step Δt", "time"),
        "critical_time_step": (traj.critical_dt, "stability limit 2/ω_max of the explicit "
                               "scheme at the start", "time"),
        "energy_error": (float(drift.max() / scale) if scale > 0 else 0.0,
                         "largest |E(t) − E(0)| over the largest kinetic energy", "1"),
        "n_nodes": (len(X), "mesh nodes", "1"),
        "n_triangles": (len(tri), "mesh triangles", "1"),
        "lam": (body.lam, "Lamé constant λ", "force / length^2"),
        "mu": (body.mu, "shear modulus μ", "force / length^2"),
        "density": (body.density, "mass density ρ", "mass / length^3")}
    for k, (value, long, units) in scalars.items():
        ds[k] = ((), value, {"long_name": long, "units": units})
    ds["gravity"] = (("dim",), np.asarray(body.gravity, float), {
        "long_name": "gravitational acceleration g", "units": "length / time^2"})
    ds.attrs["title"] = (f"neo-Hookean elastodynamics, {len(tri)} triangles, {mass_kind} mass, "
                         f"{int(traj.step[-1])} steps of {dt:g}")
    return ds
