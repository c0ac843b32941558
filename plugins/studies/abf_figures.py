"""Figures of the ABF studies: free-energy profiles with their error bands."""
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
