"""Figures of the ABF studies: free-energy profiles with their error bands, 2-D free-energy
maps with samples and minima."""
from __future__ import annotations

import numpy as np


def profile_figure(ds, coord: str):
    """A_ABF and A_US against ``coord`` with ±2 standard-error bands."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.5, 3.6), layout="constrained")
    ax = fig.subplots()
    x = ds[coord].values
    for name, label in (("free_energy_umbrella", "umbrella sampling + MBAR"),
                        ("free_energy_abf", "eABF (CZAR)")):
        if name not in ds:
            continue
        y, err = ds[name].values, ds[f"{name}_error"].values
        line, = ax.plot(x, y, label=label)
        ax.fill_between(x, y - 2 * err, y + 2 * err, color=line.get_color(), alpha=0.3)
    ax.set_xlabel(f"{ds[coord].attrs.get('long_name', coord)} "
                  f"({ds[coord].attrs.get('units', '')})")
    ax.set_ylabel("free energy (kJ/mol)")
    if "rms_difference" in ds:
        ax.set_title(f"RMS difference {float(ds['rms_difference']):.2f} kJ/mol", fontsize=9)
    ax.legend()
    finite = np.isfinite(x)
    if finite.any():
        ax.set_xlim(np.min(x[finite]), np.max(x[finite]))
    return fig


def _map(ax, x, y, A, label):
    import numpy.ma as ma

    m = ax.pcolormesh(x, y, ma.masked_invalid(np.asarray(A).T), shading="nearest",
                      cmap="viridis")
    cb = ax.figure.colorbar(m, ax=ax)
    cb.set_label(label)
    return m


def phipsi_map_figure(ds):
    """A(φ, ψ) of the reference with the training and SandCV-biased samples on top and the
    basin minima of both estimates."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.5, 5.2), layout="constrained")
    ax = fig.subplots()
    _map(ax, ds["phi"].values, ds["psi"].values, ds["free_energy_phi_psi"].values,
         "free energy A(φ, ψ) (kJ/mol)")
    for name, style, label in (("training_dihedrals", dict(c="white", s=2, alpha=0.5),
                                "training frames"),
                               ("biased_dihedrals", dict(c="red", s=2, alpha=0.4),
                                "SandCV-biased samples")):
        p = ds[name].values[::max(1, len(ds[name]) // 3000)]
        ax.scatter(p[:, 0], p[:, 1], label=label, **style)
    for name, marker, label in (("reference_minimum", "x", "minima of A(φ, ψ)"),
                                ("sandcv_minimum", "+", "minima of A(ξ) mapped")):
        p = ds[name].values
        ax.scatter(p[:, 0], p[:, 1], marker=marker, s=90, c="black", label=label)
    ax.set(xlabel="φ (degree)", ylabel="ψ (degree)", xlim=(-180, 180), ylim=(-180, 180))
    leg = ax.legend(loc="lower left", fontsize=7)
    for h in leg.legend_handles:
        h.set_sizes([20])
    return fig


def cv_map_figure(ds):
    """A(ξ₁, ξ₂) from eABF on the SandCV."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.5, 4.2), layout="constrained")
    ax = fig.subplots()
    _map(ax, ds["xi1"].values, ds["xi2"].values, ds["free_energy_cv"].values,
         "free energy A(ξ) (kJ/mol)")
    ax.set(xlabel="ξ₁", ylabel="ξ₂")
    ax.set_aspect("equal")
    return fig
