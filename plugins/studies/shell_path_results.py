"""A shell's load path as an xarray Dataset, its comparison with published curves, figures.

Dims: ``increment`` (converged states), ``point`` (monitored points, named as in the
published table), ``sample`` (sampled points of the cloud), ``dim`` (x, y, z), ``support``
(index into physics.supports), ``reference_level`` (tabulated load factors). Published
curves are compared where the path first reaches each tabulated load (:func:`first_crossing`,
what a force-controlled experiment reports), and the error is split at
``reference_split_level`` into before/after a snap-through (Sze et al. 2004 give separate
bars for both).
"""
from __future__ import annotations

import numpy as np

ONE = {"units": "1"}


def first_crossing(levels, lam, values) -> np.ndarray:
    """values interpolated at each load level where the path λ(increment) first reaches it
    (NaN if never): what force control would report, even when an arc-length path turns
    back at a limit point (the later crossings of a level lie on the unstable branch and on
    the branch the snap-through lands on; the table lists the first)."""
    lam = np.concatenate([[0.0], np.asarray(lam, float)])
    values = np.concatenate([[0.0], np.asarray(values, float)])
    out = np.full(len(levels), np.nan)
    for i, level in enumerate(levels):
        for k in range(len(lam) - 1):
            a, b = lam[k], lam[k + 1]
            if b > a and a - 1e-12 <= level <= b + 1e-12 * max(1.0, abs(b)):
                t = min(max((level - a) / (b - a), 0.0), 1.0)
                out[i] = (1 - t) * values[k] + t * values[k + 1]
                break
    return out


def path_dataset(study, dof: int, points, records, values, names, fields, loads):
    """The Dataset of a path: ``study`` is the ShellPathSettings (monitor and reference
    options), ``loads`` one (load, long_name) pair per increment, ``fields`` one (u, energy
    density) pair per increment at the sampled ``points``."""
    import xarray as xr

    mon = np.asarray(values, dtype=float).reshape(len(records), len(names))
    if study.monitor_magnitude:
        mon = np.abs(mon)
    lam = np.array([r.load_factor for r in records])
    its = np.array([r.iterations for r in records])
    secs = np.array([r.seconds for r in records])
    data = {
        "load_factor": (("increment",), lam, {**ONE, "long_name": "load factor λ"}),
        "load": (("increment",), np.array([p[0] for p in loads], dtype=float), {
            "long_name": loads[-1][1] if loads else "load", "units": "force"}),
        study.monitor_variable: (("increment", "point"), mon, {
            "long_name": "displacement at the monitored point along its direction"
                         + (" (magnitude)" if study.monitor_magnitude else ""),
            "units": "length"}),
        "newton_iterations": (("increment",), its, {**ONE, "long_name": "Newton iterations"}),
        "stable": (("increment",), np.array([r.stable for r in records], np.int8), {
            **ONE, "long_name": "1 if no negative pivot of the constrained tangent"}),
        "negative_pivots": (("increment",), np.array([r.negative_pivots for r in records],
                                                     np.int32), {
            **ONE, "long_name": "negative pivots of the factorised constrained tangent "
                                "(-1: not computed)"}),
        "snapped": (("increment",), np.array([r.snapped for r in records], np.int8), {
            **ONE, "long_name": "1 if reaching it needed more than plain Newton (a step cut "
                                "by the energy line search, an indefinite tangent or a kick off "
                                "a saddle): a snap (study.stable_path)"}),
        "increment_time": (("increment",), secs, {"long_name": "wall time of the increment",
                                                  "units": "s"}),
        "time_per_newton_iteration": ((), float(secs.sum() / its.sum()) if its.sum() else
                                      np.nan, {"long_name": "mean wall time per Newton "
                                               "iteration", "units": "s"}),
        "dof": ((), dof, {**ONE, "long_name": "degrees of freedom"}),
    }
    for j, name in enumerate(study.monitor_variables):
        data[name] = (("increment",), mon[:, j], {
            "long_name": f"displacement at {names[j]} along its direction", "units": "length"})
    reactions = [r.reactions for r in records if r.reactions is not None]
    if reactions and len(reactions) == len(records):
        data["reaction"] = (("increment", "support", "dim"), np.stack(reactions), {
            "long_name": "resultant force each support exerts on the shell", "units": "force"})
    if len(fields) == len(records) and records:
        w = np.stack([f[1] for f in fields])
        data["position"] = (("sample", "dim"), points, {
            "long_name": "sampled point x_a (reference configuration)", "units": "length"})
        data["displacement_field"] = (("increment", "sample", "dim"),
                                      np.stack([f[0] for f in fields]), {
            "long_name": "displacement u(x_a) at the sampled points", "units": "length"})
        data["energy_density"] = (("increment", "sample"), w[:, :, 2], {
            "long_name": "strain energy per unit reference area (membrane + bending)",
            "units": "energy/length²"})
        data["bending_fraction"] = (("increment", "sample"), w[:, :, 1] / np.where(
            w[:, :, 2] > 0, w[:, :, 2], 1.0), {**ONE, "long_name":
                                               "bending share of the energy density"})
    for part in ("membrane", "bending", "total"):
        data[f"energy_{part}"] = (("increment",), [r.energy.get(part, np.nan) for r in records],
                                  {"long_name": f"{part} strain energy", "units": "energy"})
    ds = xr.Dataset(data, coords={
        "increment": ("increment", np.arange(len(records)), {**ONE, "long_name": "increment"}),
        "point": ("point", names, {**ONE, "long_name": "monitored point"}),
        "dim": ("dim", ["x", "y", "z"], {**ONE, "long_name": "Cartesian component"}),
        "sample": ("sample", np.arange(len(points)), {**ONE,
                                                      "long_name": "sampled point index"})})
    if "reaction" in ds:
        ds = ds.assign_coords(support=("support", np.arange(ds.sizes["support"]), {
            **ONE, "long_name": "index into physics.supports"}))
    if study.reference_load_factors and len(records):
        ds = compare_with_reference(ds, study, lam, mon, names)
    return ds


def compare_with_reference(ds, study, lam, mon, names):
    """Adds ``reference_curve``, ``relative_error_curve`` (point, reference_level) and the
    largest errors overall and before/after ``study.reference_split_level``."""
    ref = np.asarray(study.reference_values, float).reshape(len(names), -1)
    lf = np.asarray(study.reference_load_factors, float)
    ours = np.array([first_crossing(lf, lam, mon[:, j]) for j in range(len(names))])
    err = np.abs(ours - ref) / np.abs(ref)
    ds = ds.assign_coords(reference_level=("reference_level", lf, {
        **ONE, "long_name": "tabulated load factor"}))
    ds["reference_curve"] = (("point", "reference_level"), ref, {
        "long_name": f"published values ({study.reference_label})", "units": "length"})
    ds["relative_error_curve"] = (("point", "reference_level"), err, {
        **ONE, "long_name": "|ours − published| / |published| at tabulated levels"})

    def worst(mask):
        e = err[:, mask]
        return float(np.nanmax(e)) if e.size and np.isfinite(e).any() else np.nan

    ds["max_relative_error"] = ((), worst(np.ones(len(lf), bool)), {
        **ONE, "long_name": "largest relative error over the table"})
    split = study.reference_split_level
    if split is not None:
        ds["max_relative_error_before"] = ((), worst(lf <= split), {
            **ONE, "long_name": f"largest relative error at tabulated levels ≤ {split:g}"})
        ds["max_relative_error_after"] = ((), worst(lf > split), {
            **ONE, "long_name": f"largest relative error at tabulated levels > {split:g}"})
    return ds


def path_figures(ds):
    """Load–deflection curves (published points as squares, unstable increments as
    crosses) and four energy-density snapshots of the deformed shell."""
    from matplotlib.figure import Figure

    var = [v for v in ds.data_vars if ds[v].dims == ("increment", "point")][0]
    fig = Figure(figsize=(5.6, 4.0), layout="constrained")
    ax = fig.add_subplot()
    unstable = ds["stable"].values == 0
    full = float(ds["load"].values[-1] / ds["load_factor"].values[-1]) \
        if ds.sizes["increment"] and ds["load_factor"].values[-1] else 1.0
    for j, name in enumerate(ds["point"].values):
        x, y = ds[var].values[:, j], ds["load"].values
        ax.plot(x, y, "o-", ms=3, label=f"{name}")
        if unstable.any():
            ax.plot(x[unstable], y[unstable], "rx", ms=6,
                    label="unstable (negative pivot)" if j == 0 else None)
        if "reference_curve" in ds:
            ax.plot(ds["reference_curve"].values[j], ds["reference_level"].values * full,
                    "ks", mfc="none", ms=5, label=f"{name} published" if j == 0 else None)
    ax.set_xlabel(f"{var} (length)")
    ax.set_ylabel("load")
    ax.legend(fontsize=8)
    title = "Load–deflection curves"
    if "max_relative_error" in ds:
        title += f" (max rel. error vs published {float(ds['max_relative_error']):.2%}"
        if "max_relative_error_before" in ds:
            title += (f"; before/after the snap {float(ds['max_relative_error_before']):.2%}"
                      f" / {float(ds['max_relative_error_after']):.2%}")
        title += ")"
    figures = [(title, fig)]
    if "energy_density" in ds and ds.sizes["increment"]:
        from .shell_figures import pick_snapshots, snapshot_figure

        picks = pick_snapshots(ds.sizes["increment"], 4)
        figures.append((
            "Deformed configurations (not magnified) coloured by strain energy density",
            snapshot_figure(ds["position"].values,
                            [ds["displacement_field"].values[k] for k in picks],
                            [ds["energy_density"].values[k] for k in picks],
                            [f"increment {k + 1}: load {float(ds['load'].values[k]):.4g}"
                             for k in picks])))
    return figures
