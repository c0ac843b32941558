"""Convergence of a shell benchmark over a resolution sweep: table, rate and figures.

From a sweep Dataset (``pointatlas.open_sweep``) of the ``shell`` study: DOF, displacement at
the reference point, relative error against each published value and the time split. The
rate is the least-squares slope of log(error) against log(DOF) over the last three
refinements (thesis Figs. 7, 9, 11, 13 show a line of slope two against DOF^{1/2}, i.e. the
error ~ DOF^{-1} of a second-order method in 2-D).
"""
from __future__ import annotations

import numpy as np

STAGES = ("boundary", "partition", "charts", "quadrature", "assembly", "loads", "constraints",
          "solve", "post")


def convergence_table(ds) -> dict:
    """Runs sorted by DOF: dof, displacement, errors (runs, references), times, rate."""
    run_dims = list(ds["dof"].dims)
    flat = ds.stack(run=run_dims) if run_dims else ds.expand_dims(run=[0])
    dof = np.asarray(flat["dof"].values, dtype=float)
    order = np.argsort(dof)
    disp = np.asarray(flat["displacement"].values, dtype=float)[order]
    refs = np.asarray(ds["reference_value"].values, dtype=float)
    if refs.ndim > 1:  # the same references in every run
        refs = refs.reshape(-1, refs.shape[-1])[0]
    labels = [str(v) for v in ds["reference"].values] if "reference" in ds.coords else []
    errors = np.abs(disp[:, None] - refs[None, :]) / np.abs(refs[None, :])
    times = {s: np.asarray(flat[f"time_{s}"].values, dtype=float)[order]
             for s in STAGES if f"time_{s}" in flat}
    wall = (np.asarray(flat["wall_time_s"].values, dtype=float)[order]
            if "wall_time_s" in flat else None)
    return {"dof": dof[order], "displacement": disp, "references": refs, "labels": labels,
            "errors": errors, "times": times, "wall_time": wall,
            "rate": last_rate(dof[order], errors[:, 0]) if len(refs) else float("nan"),
            "monotone": bool(len(refs) and monotone_tail(errors[:, 0]))}


def last_rate(dof: np.ndarray, error: np.ndarray, n: int = 3) -> float:
    """Slope of log(error) vs log(DOF) over the last ``n`` points (negative: converging)."""
    if len(dof) < 2:
        return float("nan")
    x, y = np.log(dof[-n:]), np.log(np.maximum(error[-n:], 1e-300))
    return float(np.polyfit(x, y, 1)[0])


def monotone_tail(error: np.ndarray, n: int = 3) -> bool:
    """True if the error decreases strictly over the last ``n`` refinements."""
    tail = error[-n:]
    return len(tail) >= 2 and bool(np.all(np.diff(tail) < 0))


def convergence_figures(ds) -> list:
    """[(title, Figure)]: error vs DOF (log–log, slope-1 guide), displacement vs DOF with the
    published values, and the time split per stage."""
    from matplotlib.figure import Figure

    t = convergence_table(ds)
    figs = []
    fig = Figure(figsize=(5.6, 4.0), layout="constrained")
    ax = fig.add_subplot()
    for j, lab in enumerate(t["labels"] or ["reference"]):
        ax.loglog(t["dof"], t["errors"][:, j], "o-", label=f"vs {lab}")
    if len(t["dof"]) >= 2:
        d0, e0 = t["dof"][0], t["errors"][0, 0]
        ax.loglog(t["dof"], e0 * (t["dof"] / d0) ** -1.0, "k--", lw=0.8, label="slope −1")
    ax.set_xlabel("DOF")
    ax.set_ylabel("relative error of the reference displacement")
    ax.legend(fontsize=8)
    rate = t["rate"]
    figs.append((f"Relative error vs DOF (rate over the last three refinements: {rate:.2f}; "
                 f"monotone: {'yes' if t['monotone'] else 'no'})", fig))
    fig = Figure(figsize=(5.6, 4.0), layout="constrained")
    ax = fig.add_subplot()
    ax.semilogx(t["dof"], t["displacement"], "o-", label="computed")
    for j, lab in enumerate(t["labels"]):
        ax.axhline(t["references"][j], ls="--", lw=0.8, color=f"C{j + 1}", label=lab)
    ax.set_xlabel("DOF")
    ax.set_ylabel("displacement at the reference point")
    ax.legend(fontsize=8)
    figs.append(("Displacement vs DOF with the published values", fig))
    if t["times"]:
        fig = Figure(figsize=(5.6, 4.0), layout="constrained")
        ax = fig.add_subplot()
        bottom = np.zeros(len(t["dof"]))
        xs = np.arange(len(t["dof"]))
        for s, v in t["times"].items():
            ax.bar(xs, v, bottom=bottom, label=s)
            bottom += v
        ax.set_xticks(xs, [str(int(d)) for d in t["dof"]])
        ax.set_xlabel("DOF")
        ax.set_ylabel("wall time (s)")
        ax.legend(fontsize=7)
        figs.append(("Time split per stage", fig))
    return figs
