"""Figures of the ``stokes_swimming`` study: tractions and velocities along the generating
curve, refinement and amplitude studies on log–log axes, a stroke's speed and position, and
error against the number of elements over a sweep."""
from __future__ import annotations

import numpy as np

COMPONENTS = {"r": "radial", "z": "axial", "phi": "azimuthal"}


def _figure():
    from matplotlib.figure import Figure

    return Figure(figsize=(5.8, 3.8), layout="constrained")


def along_curve(ds, phase: int = 0):
    """Traction (total and exterior) and surface velocity against arclength at one phase."""
    fig = _figure()
    ax1, ax2 = fig.subplots(1, 2)
    s = ds["arclength"].values[phase]
    for k, c in enumerate(ds["component"].values):
        f = ds["traction"].values[phase, :, k]
        if np.abs(f).max() > 0:
            ax1.plot(s, f, "-", label=f"{COMPONENTS[str(c)]} (in + out)", color=f"C{k}")
            ax1.plot(s, ds["traction_out"].values[phase, :, k], "--", color=f"C{k}",
                     label=f"{COMPONENTS[str(c)]} (out)")
        v = ds["surface_velocity"].values[phase, :, k]
        if np.abs(v).max() > 0:
            ax2.plot(s, v, "-", color=f"C{k}", label=COMPONENTS[str(c)])
    ax1.set_xlabel("arclength from the top pole")
    ax1.set_ylabel("traction on the fluid")
    ax1.legend(fontsize=7)
    ax2.set_xlabel("arclength from the top pole")
    ax2.set_ylabel("surface velocity")
    ax2.legend(fontsize=7)
    return fig


def refinement_figure(ds):
    n = ds["refinement_n_elements"].values.astype(float)
    e = ds["refinement_error"].values
    fig = _figure()
    ax = fig.add_subplot()
    ax.loglog(n, e, "o-", label="computed")
    if len(n) >= 2:
        ax.loglog(n, e[0] * (n / n[0]) ** -3.0, "k--", lw=0.8, label="slope −3")
    ax.set_xlabel("boundary elements")
    ax.set_ylabel("relative error")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def stroke_figure(ds):
    t = ds["time"].values
    fig = _figure()
    ax1, ax2 = fig.subplots(1, 2)
    ax1.plot(t, ds["translation_velocity"].values, label="V_c")
    ax1.plot(t, ds["rotation_rate"].values, label="ω")
    ax1.set_xlabel("time")
    ax1.set_ylabel("rigid velocities")
    ax1.legend(fontsize=8)
    ax2.plot(t, ds["position"].values, label="X(t)")
    ax2.plot(t, ds["angle"].values / (2 * np.pi), label="θ(t)/2π")
    ax2.set_xlabel("time")
    ax2.set_ylabel("displacement, rotation/2π")
    ax2.legend(fontsize=8)
    return fig


def amplitude_figure(ds):
    eps = ds["amplitude"].values
    fig = _figure()
    ax = fig.add_subplot()
    ax.loglog(eps, np.abs(ds["amplitude_net_displacement"].values), "o-", label="boundary "
              "elements")
    ax.loglog(eps, np.abs(ds["amplitude_theory"].values), "k--", lw=0.8,
              label="second-order theory")
    ax.set_xlabel("amplitude ε")
    ax.set_ylabel("|net displacement per stroke|")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def run_figures(ds) -> list:
    figs = []
    if "traction" in ds:
        figs.append(("Traction and surface velocity along the generating curve"
                     + (" (first sample)" if ds.sizes.get("phase", 1) > 1 else ""),
                     along_curve(ds)))
    if "refinement_error" in ds:
        rate = ds["refinement_rate"].values[-1]
        figs.append((f"Relative error against the number of elements (last rate {rate:.2f})",
                     refinement_figure(ds)))
    if "position" in ds and "time" in ds.coords:
        figs.append(("Rigid velocities and displacement over the stroke", stroke_figure(ds)))
    if "amplitude_net_displacement" in ds:
        figs.append((f"Net displacement against amplitude (slope "
                     f"{float(ds['amplitude_exponent']):.3f})", amplitude_figure(ds)))
    return figs


def sweep_figures(ds) -> list:
    """|relative error| against physics.n_elements on log–log axes, when swept."""
    if "relative_error" not in ds or "n_elements" not in ds:
        return []
    n = np.asarray(ds["n_elements"].values, float).ravel()
    e = np.asarray(ds["relative_error"].values, float).ravel()
    keep = np.isfinite(n) & np.isfinite(e) & (e > 0)
    if keep.sum() < 2:
        return []
    order = np.argsort(n[keep])
    n, e = n[keep][order], e[keep][order]
    fig = _figure()
    ax = fig.add_subplot()
    ax.loglog(n, e, "o-")
    rate = float(np.polyfit(np.log(n), np.log(e), 1)[0])
    ax.set_xlabel("boundary elements")
    ax.set_ylabel("relative error")
    ax.grid(True, which="both", alpha=0.3)
    return [(f"Relative error against the number of elements (fitted slope {rate:.2f})", fig)]
