"""Solved shapes and strokes as xarray Datasets (dims ``phase``, ``element``, ``component``).

Tractions are forces per area exerted by the surface on the fluid (f = −σ n for the outer
fluid, SI Eq. S11), in the units of viscosity × velocity / length; velocities in
length/time; components radial, axial, azimuthal (``r``, ``z``, ``phi``).
"""
from __future__ import annotations

import numpy as np

L, V, F = "length", "length / time", "viscosity * length / time"
ONE = {"units": "1"}


def shapes_dataset(solved, times=None):
    """Per-phase Dataset of [(Elements, ShapeSolution)] (one entry: a single shape)."""
    import xarray as xr

    els = [e for e, _ in solved]
    sols = [s for _, s in solved]
    n = els[0].n
    K = len(solved)
    stack = lambda f: np.stack([f(e, s) for e, s in solved])  # noqa: E731
    ds = xr.Dataset(coords={
        "phase": ("phase", np.arange(K), {"long_name": "sample of the stroke", **ONE}),
        "element": ("element", np.arange(n), {"long_name": "boundary element", **ONE}),
        "component": ("component", ["r", "z", "phi"], {"long_name": "cylindrical component "
                                                       "(radial, axial, azimuthal)", **ONE}),
        "arclength": (("phase", "element"), stack(lambda e, s: e.arclength), {
            "long_name": "arclength from the top pole to the element's collocation point",
            "units": L})})
    if times is not None:
        ds = ds.assign_coords(time=("phase", np.asarray(times, float), {
            "long_name": "time of the sample", "units": "time"}))
    ds["collocation_point"] = (("phase", "element", "rz"), stack(lambda e, s: e.x_mid), {
        "long_name": "collocation point (r, z) on the generating curve", "units": L})
    ds["traction"] = (("phase", "element", "component"), stack(lambda e, s: s.traction), {
        "long_name": "traction on the fluid, interior + exterior (f_inn + f_out)", "units": F})
    ds["traction_out"] = (("phase", "element", "component"), stack(
        lambda e, s: s.traction_out), {"long_name": "traction on the exterior fluid f_out",
                                       "units": F})
    ds["surface_velocity"] = (("phase", "element", "component"), stack(
        lambda e, s: s.velocity), {"long_name": "surface velocity at the collocation points "
                                   "(rigid motion and permeation included)", "units": V})
    for name, attr, long, units in (
            ("translation_velocity", "translation", "rigid translation V_c along +z", V),
            ("rotation_rate", "rotation", "rigid rotation ω about +z", "1 / time"),
            ("axial_force", "force", "axial force of the surface on the fluid", F + " * length"),
            ("axial_torque", "torque", "axial torque of the surface on the fluid",
             F + " * length^2"),
            ("power_out", "power_out", "power into the exterior fluid ∫ f_out·v dS",
             F + " * length * length / time"),
            ("power_inner_outer", "power_total",
             "power into interior + exterior fluid ∫ (f_inn + f_out)·v dS",
             F + " * length * length / time"),
            ("volume_rate", "volume_rate", "rate of change of volume V̇ = ∫ v·n dS",
             "length^3 / time"),
            ("permeation_velocity", "permeation", "uniform permeation normal velocity −V̇/S",
             V),
            ("gauge_multiplier", "gauge", "Lagrange multiplier of ∫ f·n dS = 0 (≈ 0 when "
             "∫ v·n dS = 0)", V)):
        ds[name] = (("phase",), np.array([getattr(s, attr) for s in sols]),
                    {"long_name": long, "units": units})
    ds["n_elements"] = ((), n, {"long_name": "boundary elements per shape", **ONE})
    return ds


def stroke_dataset(sol, body_length: float):
    """:func:`shapes_dataset` plus the stroke's integrals (:mod:`.stroke`)."""
    ds = shapes_dataset(sol.shapes, sol.times)
    net = float(sol.position[-1])
    ds["position"] = (("phase",), sol.position, {"long_name": "displacement X(t) = ∫ V_c dt "
                                                 "(trapezoidal rule)", "units": L})
    ds["angle"] = (("phase",), sol.angle, {"long_name": "rotation θ(t) = ∫ ω dt", "units": "rad"})
    ds["mean_shape"] = (("node", "rz"), sol.mean_shape, {
        "long_name": "time-averaged generating curve", "units": L})
    scalars = {
        "period": (sol.period, "period T of the stroke", "time"),
        "net_displacement": (net, "net displacement per stroke X(T)", L),
        "net_displacement_body_lengths": (net / body_length, "net displacement per stroke "
                                          "in body lengths (pole-to-pole length of the mean "
                                          "shape)", "1"),
        "net_rotation": (float(sol.angle[-1]) / (2 * np.pi), "net rotation per stroke Δθ/2π",
                         "1"),
        "mean_speed": (sol.mean_speed, "mean speed Ū = X(T)/T", V),
        "body_length": (body_length, "pole-to-pole length of the mean shape", L),
        "mean_power_out": (sol.mean_power_out, "mean exterior power P̄_out",
                           F + " * length * length / time"),
        "mean_power_inner_outer": (sol.mean_power_total, "mean interior + exterior power "
                                   "P̄_inn+out", F + " * length * length / time"),
        "drag_per_speed": (sol.drag_per_speed, "drag of the mean shape per unit speed",
                           F + " * length"),
        "efficiency_out": (sol.efficiency(sol.mean_power_out), "Lighthill efficiency "
                           "F_U Ū² / P̄_out", "1"),
        "efficiency_inner_outer": (sol.efficiency(sol.mean_power_total),
                                   "Lighthill efficiency F_U Ū² / P̄_inn+out", "1")}
    for k, (v, long, units) in scalars.items():
        ds[k] = ((), float(v), {"long_name": long, "units": units})
    return ds
