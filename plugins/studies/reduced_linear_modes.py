"""Linear (PCA) reduction of a small vibration of the full model against its modal
truncation (issue 21's ``rom_linear_modes``).

The full model is the ``physics`` (``neo_hookean_2d``, through ``build_body`` and ``solve``).
With K and M (lumped) at the reference configuration on the free DOFs, its lowest modes
solve K φ_i = ω_i² M φ_i (``scipy.sparse.linalg.eigsh``, shift-invert). Released from rest at
x₀ = X + a Σ_{i≤d} φ_i/max|φ_i| (``amplitude`` a × the body's height), the linear theory
truncated to those d modes is x(t) = X + a Σ φ_i/max|φ_i| cos ω_i t. The full model's
explicit trajectory over ``snapshot_periods`` periods of mode 1 gives the snapshots; the
``embedder`` (PCA, d components) the affine manifold x̄ + Pᵀq
(:mod:`pointatlas_reduction.affine_manifold`); the reduced Lagrangian and the variational
integrator (α = ``alpha``, Δt = T_d/``steps_per_period``) the reduced trajectory over
``periods`` periods of mode 1. ``relative_error`` = max over d ∈ ``n_modes`` of
max_t ‖x_r(t) − x_modal(t)‖ / max_t ‖x_modal(t) − X‖ (the DOFs' Euclidean norm).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, List

import numpy as np

from pointatlas.constraints import Each, Interval
from pointatlas.stores_config import stores_config


@dataclass
class ReducedLinearModesSettings:
    n_modes: List[int] = field(default_factory=lambda: [1, 2, 3])
    amplitude: float = 1e-7
    snapshot_periods: float = 1.5
    periods: float = 2.0
    steps_per_period: int = 200
    alpha: float = 0.5
    parameter_constraints: ClassVar[dict] = {
        "n_modes": [Each(Interval(int, 1, 50))],
        "amplitude": [Interval(float, 0, 1e-2, closed="right")],
        "snapshot_periods": [Interval(float, 0.5, None)], "periods": [Interval(float, 0.1, None)],
        "steps_per_period": [Interval(int, 20, None)], "alpha": [Interval(float, 0, 1)]}


def lowest_modes(K, M_diag, k: int):
    """(ω (k,), Φ (D, k)) of K φ = ω² M φ with M diagonal, by shift-invert about 0."""
    from scipy.sparse import diags
    from scipy.sparse.linalg import eigsh

    w2, Phi = eigsh(K, k=k, M=diags(M_diag), sigma=0.0, which="LM")
    order = np.argsort(w2)
    return np.sqrt(w2[order]), Phi[:, order]


@stores_config
class ReducedLinearModes:
    """PCA reduction of a small vibration against the modal truncation."""

    Config = ReducedLinearModesSettings
    description: ClassVar[str] = ("PCA reduction of a small vibration of neo_hookean_2d, "
                                  "integrated variationally, against its modal truncation.")

    def run(self, ctx):
        import xarray as xr

        from pointatlas.errors import ConfigError
        from pointatlas_reduction.affine_manifold import AffineManifold
        from pointatlas_reduction.reduced_lagrangian import ReducedLagrangian
        from pointatlas_reduction.variational_integrator import integrate

        physics = ctx.plugin("physics")
        if not hasattr(physics, "build_body"):
            raise ConfigError("study=reduced_linear_modes needs an elastic body "
                              "(physics=neo_hookean_2d).")
        body = physics.build_body()
        X = body.reference
        free = body.free_dofs
        Mf = np.repeat(body.nodal_masses, 2)[free]
        K = body.tangent(X).tocsr()[free][:, free]
        dmax = max(self.n_modes)
        omega, Phi = lowest_modes(K, Mf, dmax)
        Phi = Phi / np.abs(Phi).max(axis=0)
        a = self.amplitude * float(np.ptp(X[:, 1]))
        T1 = 2 * np.pi / omega[0]

        def full_x(xf):
            x = X.copy().reshape(-1)
            x[free] = xf
            return x.reshape(-1, 2)

        def potential(xf):
            x = full_x(xf)
            return body.potential_energy(x), -body.forces(x).reshape(-1)[free]

        rows, errors = [], []
        for d in sorted(self.n_modes):
            x0f = X.reshape(-1)[free] + a * Phi[:, :d].sum(axis=1)
            n_full = int(np.ceil(self.snapshot_periods * T1 / float(physics.dt)))
            with ctx.timed(f"full_{d}"):
                traj = physics.solve(ctx, x0=full_x(x0f), v0=np.zeros_like(X), n_steps=n_full)
            S = traj["position"].values.reshape(len(traj["time"]), -1)[:, free]
            pca = ctx.plugin("embedder", n_components=d).fit(S)
            manifold = AffineManifold(pca.mean_, pca.components_)
            RL = ReducedLagrangian(manifold, Mf, potential)
            q0, _ = manifold.project(x0f)
            dt = 2 * np.pi / omega[d - 1] / self.steps_per_period
            n = int(np.ceil(self.periods * T1 / dt))
            with ctx.timed(f"reduced_{d}"):
                tr = integrate(RL.terms, q0, np.zeros(d), dt, n, alpha=self.alpha)
            xr_ = manifold.evaluate(tr.q)                              # (steps, D_free)
            modal = X.reshape(-1)[free] + a * np.cos(np.outer(tr.time, omega[:d])) @ Phi[:, :d].T
            err = (np.linalg.norm(xr_ - modal, axis=1).max()
                   / np.linalg.norm(modal - X.reshape(-1)[free], axis=1).max())
            rows.append((d, err, len(S), n, dt))
            errors.append(err)
            ctx.log.info("d = %d: PCA on %d snapshots, %d reduced steps of %.3g: relative "
                         "error against the %d-mode truncation %.3e", d, len(S), n, dt, d, err)
        R = np.array(rows)
        ds = xr.Dataset(coords={"n_components": ("n_components", R[:, 0].astype(int), {
            "long_name": "retained modes d", "units": "1"}),
            "mode": ("mode", np.arange(1, dmax + 1), {"long_name": "mode", "units": "1"})})
        ds["mode_error"] = (("n_components",), R[:, 1], {
            "long_name": "max_t |x_r − x_modal| / max_t |x_modal − X|", "units": "1"})
        ds["angular_frequency"] = (("mode",), omega, {"long_name": "ω_i of K φ = ω² M φ",
                                                       "units": "rad/s"})
        ds["relative_error"] = ((), float(max(errors)), {
            "long_name": "max over d of the reduced trajectory's error against the d-mode "
                         "truncation", "units": "1"})
        ds["n_nodes"] = ((), int(body.mesh.n_nodes), {"long_name": "mesh nodes", "units": "1"})
        ds.attrs["title"] = "PCA reduction against the modal truncation"
        return ds
