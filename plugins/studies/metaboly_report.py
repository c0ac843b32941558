"""The Dataset of a metaboly run: per frame (``frame``, coord ``time``), per stroke sample
(``phase``), the material nodes (``lambda``) and the headline scalars (the contract:
``shape_error``, ``period_error``, ``speed_error``, ``displacement_per_stroke``,
``n_dropped_frames``, beside U, Δθ/2π, powers, efficiencies, γ_max, v̄ min/mean/max and
the number of cycles)."""
from __future__ import annotations

import numpy as np

ONE = "1"


def _v(dims, values, long_name, units=ONE):
    return (dims, values, {"long_name": long_name, "units": units})


def build_dataset(seq, proc, desc, Y, Y3, cycles, phases, shapes, kin, hyd, truth):
    import xarray as xr

    K = seq.n_frames
    order = np.argsort(seq.times, kind="stable")
    kept = np.asarray(proc["kept"], bool)
    pos = np.full(K, -1)
    pos[np.asarray(proc["index"])] = np.arange(len(proc["index"]))   # kept frame → row

    def per_frame(values, fill=np.nan):
        out = np.full(K, fill, dtype=float)
        rows = pos >= 0
        out[rows] = np.asarray(values, float)[pos[rows]]
        return out[order]

    emb = np.full((K, Y.shape[1]), np.nan)
    emb[pos >= 0] = Y[pos[pos >= 0]]
    ds = xr.Dataset(coords={
        "frame": ("frame", np.arange(K), {"long_name": "frame (time order)", "units": ONE}),
        "time": ("frame", np.asarray(seq.times, float)[order], {"long_name": "time of the "
                                                                 "frame", "units": "s"}),
        "phase": ("phase", phases, {"long_name": "phase of the stroke", "units": ONE}),
        "node": ("node", np.arange(shapes.shape[1]), {"long_name": "station of the "
                                                      "generating curve", "units": ONE}),
        "rz": ("rz", ["r", "z"], {"long_name": "radial and axial coordinate", "units": ONE}),
        "lambda": ("lambda", kin.lam, {"long_name": "body coordinate λ (area fraction)",
                                       "units": ONE}),
        "latent": ("latent", np.arange(Y.shape[1]), {"long_name": "embedding coordinate",
                                                     "units": ONE})})
    ds["kept"] = _v(("frame",), kept[order].astype(np.int8), "frame kept (1) or dropped (0)")
    ds["drop_reason"] = _v(("frame",), np.array(proc["reason"], dtype=object)[order].astype(str),
                           "why the frame was dropped ('' if kept)")
    ds["frame_phase"] = _v(("frame",), per_frame(cycles.phase), "phase of the frame in the "
                           "stroke (NaN if dropped)")
    ds["asymmetry"] = _v(("frame",), np.asarray(proc["asymmetry"], float)[order],
                         "silhouette asymmetry max|r_left − r_right| / max r")
    for key, long, units in (("reduced_volume", "reduced volume 6√π V / S^{3/2}", ONE),
                             ("area", "area of the cell", "um^2"),
                             ("volume", "volume of the cell", "um^3")):
        ds[key] = _v(("frame",), per_frame(desc[key]), long, units)
    ds["embedding"] = _v(("frame", "latent"), emb[order], "Isomap coordinates of the frame")
    emb3 = np.full((K, Y3.shape[1]), np.nan)
    emb3[pos >= 0] = Y3[pos[pos >= 0]]
    ds["embedding_3d"] = _v(("frame", "latent3"), emb3[order], "3-D Isomap coordinates")
    ds["generating_curve"] = _v(("phase", "node", "rz"), shapes, "generating curve of the "
                                "smooth stroke (LME over the phase)", "um")
    ds["shear"] = _v(("phase", "lambda"), kin.shear, "pellicle shear γ(λ, phase)")
    ds["shear_max_phase"] = _v(("phase",), kin.shear.max(axis=1), "max over λ of γ at the "
                               "phase")
    ds["translation_velocity"] = _v(("phase",), np.asarray(hyd["translation_velocity"])[:-1],
                                    "swimming velocity V_c", "um/s")
    ds["rotation_rate"] = _v(("phase",), np.asarray(hyd["rotation_rate"])[:-1],
                             "rotation rate ω", "rad/s")
    v = np.asarray(desc["reduced_volume"], float)
    U = float(hyd["net_displacement_body_lengths"])
    scalars = {
        "displacement_per_stroke": (U, "net displacement per stroke U (body lengths)"),
        "net_rotation": (float(hyd["net_rotation"]), "net rotation per stroke Δθ/2π"),
        "mean_power_out": (float(hyd["mean_power_out"]), "mean power into the outer fluid"),
        "mean_power_inner_outer": (float(hyd["mean_power_inner_outer"]), "mean power, inner "
                                   "+ outer fluid"),
        "efficiency_out": (float(hyd["efficiency_out"]), "Lighthill efficiency (out)"),
        "efficiency_inner_outer": (float(hyd["efficiency_inner_outer"]),
                                   "Lighthill efficiency (out + inner)"),
        "shear_max": (float(kin.shear_max), "γ_max over the stroke"),
        "reduced_volume_min": (float(v.min()), "min reduced volume over the frames"),
        "reduced_volume_mean": (float(v.mean()), "mean reduced volume over the frames"),
        "reduced_volume_max": (float(v.max()), "max reduced volume over the frames"),
        "area_deviation": (float(desc["area_deviation"]), "max |S − S̄|/S̄ over the frames"),
        "n_cycles": (cycles.n_cycles, "complete cycles found"),
        "period": (cycles.period, "mean period of the stroke (s)"),
        "loopness": (cycles.winding, "area swept per cycle by the embedding / circle's (1: "
                     "loop, 0: back-and-forth arc)"),
        "n_frames": (K, "frames in the sequence"),
        "n_dropped_frames": (int((~kept).sum()), "frames dropped (segmentation, border, "
                             "asymmetry)"),
        "body_length": (float(hyd["body_length"]), "pole-to-pole length of the mean shape "
                        "(um)")}
    if truth is not None:
        Ut = truth["displacement_per_stroke"]
        scalars.update({
            "shape_error": (truth["shape_error"], "max over phase of the shape distance to "
                            "the truth / body length"),
            "period_error": (truth["period_error"], "|period / true period − 1|"),
            "speed_error": (abs(U / Ut - 1.0) if abs(Ut) > 1e-6 else np.nan,
                            "|U / U_true − 1| (U_true: the same BEM on the true stroke; NaN "
                            "where |U_true| < 1e-6, a reciprocal stroke)"),
            "displacement_per_stroke_reference": (Ut, "U of the true stroke (body lengths)"),
            "shear_max_reference": (truth["shear_max"], "γ_max of the true stroke"),
            "phase_offset": (truth["phase_offset"], "true phase at recovered phase 0")})
    for k, (val, long) in scalars.items():
        units = {"period": "s", "body_length": "um"}.get(k, ONE)
        if k.startswith("mean_power"):
            units = hyd[k].attrs.get("units", ONE)
        ds[k] = _v((), val, long, units)
    ds["reference_not_realisable"] = _v((), int(kin.not_realisable), "material nodes where "
                                        "the canonical reference pellicle (SI Eq. S9) has no "
                                        "real solution (clipped)")
    if kin.warnings:                 # the pellicle's own checks: the run is flagged, not passed
        ds.attrs["warnings"] = "pellicle kinematics: " + "; ".join(kin.warnings)
    counts = proc.get("counts", {})
    ds.attrs["dropped_by_reason"] = str(counts.get("dropped_by_reason", {}))
    return ds
