"""Figures of :mod:`.rom_neo_hookean` (thesis Figs. 20–24): D and e against d for each method,
the intrinsic-dimension estimators, the two-dimensional embeddings coloured by the distance to
the first configuration (Fig. 21), the reduced mass and effective potential over the embedding,
and snapshot strips of a full and the reduced trajectories."""
from __future__ import annotations

import numpy as np


def _against_d(ds):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8.0, 3.4), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    d = ds["n_components"].values
    for m in ds["method"].values:
        for ax, var in ((ax1, "trajectory_distance"), (ax2, "reconstruction_error")):
            y = ds[var].sel({"method": m}).values
            ok = np.isfinite(y)
            if ok.any():
                ax.semilogy(d[ok], y[ok], "o-" if m == "pca" else "s", label=str(m), ms=5)
    ax1.set_xlabel("d")
    ax1.set_ylabel("trajectory distance D (Eq. 13)")
    ax2.set_xlabel("d")
    ax2.set_ylabel("reconstruction error e (Eq. 12)")
    ax1.legend()
    return fig


def _dimension(ds):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8.0, 3.2), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    s, dc = ds["correlation_scale"].values, ds["correlation_dimension"].values
    ok = np.isfinite(dc)
    ax1.semilogx(s[ok], dc[ok])
    ax1.set_xlabel("ε")
    ax1.set_ylabel("correlation dimension")
    ax2.semilogy(ds["local_dim"].values, ds["local_pca_residual"].values, "o-")
    ax2.set_xlabel("d")
    ax2.set_ylabel("local PCA residual variance")
    return fig


def _embeddings(ds, names):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(4.0 * len(names), 3.4), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(names)))
    c = ds["embedding_distance"].values
    for ax, name in zip(axes, names):
        Q = ds[f"embedding_{name}"].values
        sc = ax.scatter(Q[:, 0], Q[:, 1], c=c, s=2, cmap="viridis")
        ax.set_title(name)
        ax.set_xlabel("q₁")
        ax.set_ylabel("q₂")
    fig.colorbar(sc, ax=axes.tolist(), label="distance to the first configuration")
    return fig


def _maps(ds):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8.0, 3.2), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    q1, q2 = ds["map_q1"].values, ds["map_q2"].values
    for ax, var, label in ((ax1, "reduced_mass_trace", "tr M̃(q)"),
                           (ax2, "effective_potential", "Ṽ(q)")):
        im = ax.pcolormesh(q1, q2, ds[var].values, shading="nearest")
        fig.colorbar(im, ax=ax, label=label)
        ax.set_xlabel("q₁")
        ax.set_ylabel("q₂")
    return fig


def _strips(ds):
    from matplotlib.figure import Figure

    models = ds["strip_model"].values
    t = ds["frame_time"].values
    fig = Figure(figsize=(1.3 * len(t) + 1, 1.9 * len(models)), layout="constrained")
    axes = np.atleast_2d(fig.subplots(len(models), len(t), sharex=True, sharey=True))
    tri = ds["face_node_connectivity"].values
    P = ds["strip_position"].values
    for i, m in enumerate(models):
        for j in range(len(t)):
            ax = axes[i, j]
            x = P[i, j]
            if np.all(np.isfinite(x)):
                ax.triplot(x[:, 0], x[:, 1], tri, lw=0.2, color="C0" if i == 0 else "C3")
            else:
                ax.text(0.5, 0.5, "stopped", ha="center", transform=ax.transAxes)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            if i == 0:
                ax.set_title(f"t = {t[j]:.2f}", fontsize=8)
            if j == 0:
                ax.set_ylabel(str(m), fontsize=8)
    return fig


def _stopped(ds) -> str:
    """'; stopped early: nlie d=2 (t = 0.13, 0.40 of 1), …' from reduced_time_reached."""
    R = ds["reduced_time_reached"]
    window = float(ds["test_window"])
    out = []
    for m in ds["method"].values:
        for d in ds["n_components"].values:
            r = R.sel({"method": m, "n_components": d}).values
            if np.all(np.isfinite(r)) and np.any(r < window * (1 - 1e-9)):
                out.append(f"{m} d={d} (t = {', '.join(f'{v:.2g}' for v in r)} of "
                           f"{window:g})")
    return "; reduced runs that left the sampled region or failed Newton (no D): " + \
        ", ".join(out) if out else ""


def figures(ds):
    out = [("Trajectory distance D and reconstruction error e against the dimension d "
            "(held-out trajectories)" + _stopped(ds), _against_d(ds)),
           ("Intrinsic dimension a priori: correlation dimension and local PCA residual "
            "variance of the landmark training set", _dimension(ds))]
    names = [str(m) for m in ds["method"].values if f"embedding_{m}" in ds]
    if names:
        out.append(("Two-dimensional embeddings of the training set coloured by the distance "
                    "to the first configuration (thesis Fig. 21)", _embeddings(ds, names)))
    if "reduced_mass_trace" in ds:
        out.append(("Reduced mass (trace) and effective potential over the 2-D embedding of "
                    f"{names[0] if names else 'the nonlinear method'}", _maps(ds)))
    out.append(("A held-out trajectory: full model and reduced models at the same times",
                _strips(ds)))
    return out
