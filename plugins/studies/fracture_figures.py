"""Report figures of a fracture path (study ``fracture``), read from its Dataset only.

The load–displacement curve (reaction against the imposed displacement, with the contrast
path's when there is one), the energies along the path (elastic, fracture, the change of
their sum from the initial state, and the external work, which that change follows on a
quasi-static path), and the phase field at
four increments on the reference and on the deformed shape (displacement magnified so that
its largest value is a tenth of the specimen's size), colour bar 0–1, rendered off screen
by pyvista (:func:`.shell_figures.snapshot_figure`).
"""
from __future__ import annotations

import numpy as np


def fracture_figures(ds) -> list:
    """[(title, matplotlib Figure or PNG bytes)] of the module doc."""
    from matplotlib.figure import Figure

    split = ds.attrs.get("split", "?")
    d = ds["imposed_displacement"].values
    fig = Figure(figsize=(10.0, 3.9), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    ax1.plot(d, ds["reaction"].values, "o-", ms=3, label=f"split {split}")
    if "contrast_reaction" in ds:
        ax1.plot(ds["contrast_imposed_displacement"].values, ds["contrast_reaction"].values,
                 "s--", ms=3, label=f"split {ds.attrs.get('contrast_split', '?')}")
    ax1.set_xlabel("imposed displacement (length)")
    ax1.set_ylabel("reaction (force)")
    ax1.legend(fontsize=8)
    el, fr = ds["elastic_energy"].values, ds["fracture_energy"].values
    for y, label, style in ((el, "elastic", "o-"), (fr, "fracture", "s-"),
                            (el + fr - el[0] - fr[0], "elastic + fracture − initial", "-"),
                            (ds["external_work"].values, "external work", "k--")):
        ax2.plot(d, y, style, ms=3, label=label)
    ax2.set_xlabel("imposed displacement (length)")
    ax2.set_ylabel("energy")
    ax2.legend(fontsize=8)
    title = "Reaction and energies against the imposed displacement"
    if "relative_error" in ds and "griffith_stress" in ds:
        title += (f" (peak stress {float(ds['peak_stress']):.4g} against Griffith "
                  f"{float(ds['griffith_stress']):.4g}: {float(ds['relative_error']):+.1%})")
    figures = [(title, fig)]
    figures += phase_snapshots(ds)
    return figures


def phase_snapshots(ds) -> list:
    """The phase field at four increments, on the reference and on the deformed shape; and
    the contrast path's last phase field when there is one."""
    from .shell_figures import pick_snapshots, snapshot_figure

    n = ds.sizes["increment"]
    if n < 2:
        return []
    X = ds["position"].values
    size = float(np.linalg.norm(X.max(axis=0) - X.min(axis=0)))
    view = "xy" if np.ptp(X[:, 2]) <= 1e-9 * size else "isometric"
    picks = [1 + k for k in pick_snapshots(n - 1, 4)]
    v, u = ds["phase_field"].values, ds["displacement"].values
    umax = max(float(np.abs(u[k]).max()) for k in picks)
    mag = 0.1 * size / umax if umax > 0 else 1.0
    d = ds["imposed_displacement"].values
    titles = [f"increment {k}: imposed displacement {d[k]:.4g}" for k in picks]
    common = dict(log_scale=False, clim=(0.0, 1.0), bar_title="phase field", cmap="magma",
                  view=view)
    zero = np.zeros_like(X)
    out = [("Phase field at four increments on the reference shape (colour bar 0-1)",
            snapshot_figure(X, [zero] * len(picks), [v[k] for k in picks], titles, **common)),
           (f"Phase field on the deformed shape (displacement magnified {mag:.3g}x)",
            snapshot_figure(X, [mag * u[k] for k in picks], [v[k] for k in picks], titles,
                            **common))]
    if "contrast_phase_field" in ds:
        other = ds.attrs.get("contrast_split", "?")
        out.append((f"Phase field at the last increment: split {ds.attrs.get('split', '?')} "
                    f"(left, min away from the pre-cracks {float(ds['min_phase_field']):.3f}) "
                    f"and split {other} (right, "
                    f"{float(ds['contrast_min_phase_field']):.3f})",
                    snapshot_figure(X, [zero, zero], [v[-1], ds["contrast_phase_field"].values],
                                    [f"split {ds.attrs.get('split', '?')}", f"split {other}"],
                                    **common)))
    return out
