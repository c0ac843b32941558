"""Figures of the ``metaboly`` study: the loop in shape space, a strip of shapes round the
stroke, the pellicle shear γ(λ, phase), and the scalars beside the PNAS Table 1 row."""
from __future__ import annotations

import numpy as np


def _figure(w=6.4, h=3.8):
    from matplotlib.figure import Figure

    return Figure(figsize=(w, h), layout="constrained")


def embedding_figure(ds):
    fig = _figure(5.6, 4.2)
    ax = fig.add_subplot()
    Y = ds["embedding"].values
    ok = np.isfinite(Y).all(axis=1)
    sc = ax.scatter(Y[ok, 0], Y[ok, 1], c=ds["time"].values[ok], s=8, cmap="viridis")
    fig.colorbar(sc, ax=ax, label="time (s)")
    ax.set_xlabel("Isomap 1")
    ax.set_ylabel("Isomap 2")
    ax.set_aspect("equal", adjustable="datalim")
    return fig


def strip_figure(ds, n: int = 8):
    C = ds["generating_curve"].values
    K = C.shape[0]
    fig = _figure(8.0, 3.4)
    ax = fig.add_subplot()
    width = 2.6 * np.nanmax(C[..., 0])
    for j, k in enumerate(np.linspace(0, K, n, endpoint=False).astype(int)):
        r, z = C[k, :, 0], C[k, :, 1]
        x0 = j * width
        ax.fill(np.concatenate([x0 + r, (x0 - r)[::-1]]), np.concatenate([z, z[::-1]]),
                color="C0", alpha=0.35, lw=0)
        ax.plot(x0 + r, z, "C0", lw=0.8)
        ax.plot(x0 - r, z, "C0", lw=0.8)
        ax.text(x0, np.nanmax(C[..., 1]) * 1.08, f"φ = {float(ds['phase'][k]):.2f}",
                ha="center", fontsize=8)
    ax.set_aspect("equal")
    ax.set_axis_off()
    return fig


def shear_figure(ds):
    fig = _figure(5.6, 3.8)
    ax = fig.add_subplot()
    im = ax.imshow(ds["shear"].values.T, origin="lower", aspect="auto", cmap="magma",
                   extent=[0, 1, float(ds["lambda"][0]), float(ds["lambda"][-1])])
    fig.colorbar(im, ax=ax, label="pellicle shear γ")
    ax.set_xlabel("phase of the stroke")
    ax.set_ylabel("body coordinate λ")
    return fig


def table_figure(ds):
    from .metaboly import PNAS_EUGLENID_3 as P

    fig = _figure(8.0, 1.5)
    ax = fig.add_subplot()
    ax.set_axis_off()
    head = ["", "v̄ min/mean/max", "γ_max", "U (body lengths)", "Δθ/2π", "Eff_L out %",
            "Eff_L out+inn %"]
    row = ["this run", "/".join(f"{float(ds[k]):.2f}" for k in (
        "reduced_volume_min", "reduced_volume_mean", "reduced_volume_max")),
           f"{float(ds['shear_max']):.2f}", f"{float(ds['displacement_per_stroke']):.3f}",
           f"{float(ds['net_rotation']):.3f}", f"{100 * float(ds['efficiency_out']):.2f}",
           f"{100 * float(ds['efficiency_inner_outer']):.2f}"]
    pnas = ["PNAS #3", "/".join(f"{x:.2f}" for x in P["reduced_volume"]),
            f"{P['shear_max']:.1f}", f"{P['displacement_per_stroke']:.2f}",
            f"{P['net_rotation']:.3f}", f"{100 * P['efficiency_out']:.1f}",
            f"{100 * P['efficiency_inner_outer']:.2f}"]
    t = ax.table(cellText=[row, pnas], colLabels=head, loc="center", cellLoc="center")
    t.auto_set_font_size(False)
    t.set_fontsize(8)
    return fig


def run_figures(ds) -> list:
    return [("The frames in shape space (2-D Isomap), coloured by time", embedding_figure(ds)),
            ("Shapes round the smooth stroke", strip_figure(ds)),
            ("Pellicle shear γ(λ, phase)", shear_figure(ds)),
            ("Scalars beside the PNAS Table 1 row of Euglenid #3", table_figure(ds))]
