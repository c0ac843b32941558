"""Speed and energy behaviour of the explicit neo-Hookean model at the thesis size (issue 21).

Millán (2012) §5.2, Fig. 19: λ = 1000, μ = 500, ρ = 1, gravity, 9 428 triangles / 4 934 nodes,
explicit midpoint rule with Δt = 2·10⁻⁵. Here the stand-in column of
:func:`pointatlas_physics.neo_hookean_2d.mesh.tapered_column` at ``n_triangles=9428``
(9 416 triangles, 4 945 nodes), clamped at the bottom under g = (0, −1).

1. µs per internal-force evaluation f_int(x) and per explicit step (lumped and consistent
   mass), median of ``--repeat`` timings after a warm-up. Target: f_int well under 1 ms.
2. A free vibration of ``--steps`` (default 10⁵) steps: released from rest at the static
   equilibrium under the sideways body force ρ (1, −1), then moving under gravity alone. The
   energy error max |E(t) − E(0)| is reported over the first and the last tenth of the run,
   relative to the energy of the vibration E(0) − V(x_eq) (x_eq the equilibrium under gravity,
   V its potential: the gauge-free energy available to the motion). Target: < 10⁻³ and not
   growing.

Usage: python benchmarks/bench_neo_hookean.py [out.nc] [--steps 100000] [--repeat 5]
Writes benchmarks/results/bench_neo_hookean.nc by default.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

TARGET_FORCE_US, TARGET_DRIFT = 1000.0, 1e-3


def _median_us(fn, n, repeat):
    fn()                                                    # warm-up (numba compile)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        times.append((time.perf_counter() - t0) / n * 1e6)
    return float(np.median(times))


def main(argv=None):
    import xarray as xr

    from pointatlas_physics.neo_hookean_2d import energy
    from pointatlas_physics.neo_hookean_2d.integrator import integrate
    from pointatlas_physics.neo_hookean_2d.plugin import NeoHookean2D
    from pointatlas_physics.neo_hookean_2d.statics import static_equilibrium

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", nargs="?", default=str(Path(__file__).parent / "results" /
                                                 "bench_neo_hookean.nc"))
    p.add_argument("--steps", type=int, default=100_000)
    p.add_argument("--repeat", type=int, default=5)
    a = p.parse_args(argv)

    physics = NeoHookean2D(n_steps=a.steps, save_every=max(1, a.steps // 400),
                           initial_load=[1.0, -1.0])
    body = physics.build_body()
    n_nodes, n_tri = body.mesh.n_nodes, body.mesh.n_triangles
    tri, G, area, lam, mu = body.kernel_arrays()
    x = physics.initial_positions(body)
    f = np.empty_like(x)
    force_us = _median_us(lambda: energy.internal_forces(x, tri, G, area, lam, mu, f), 200,
                          a.repeat)
    step_us = {}
    for kind in ("lumped", "consistent"):
        mass = body.mass(kind)
        n = 200 if kind == "lumped" else 50
        step_us[kind] = _median_us(lambda: integrate(body, mass, x, np.zeros_like(x), 2e-5, n,
                                                     n, critical_dt=1.0), 1, a.repeat) / n

    class _Ctx:
        log = None

    t0 = time.perf_counter()
    ds = physics.solve(_Ctx())
    run_s = time.perf_counter() - t0
    x_eq = static_equilibrium(body).x
    E = ds["total_energy"].values
    scale = E[0] - body.potential_energy(x_eq)
    rel = np.abs(E - E[0]) / scale
    k = max(1, len(E) // 10)
    first, last = float(rel[1:k + 1].max()), float(rel[-k:].max())

    print(f"neo-Hookean column: {n_tri} triangles, {n_nodes} nodes, Δt = {physics.dt:g}, "
          f"Δt_crit = {float(ds['critical_time_step']):.3g}")
    print(f"{'quantity':<38}{'value':>12}{'target':>10}  met")
    rows = [("internal force f_int(x) [µs]", force_us, TARGET_FORCE_US),
            ("explicit step, lumped mass [µs]", step_us["lumped"], None),
            ("explicit step, consistent mass [µs]", step_us["consistent"], None),
            (f"{a.steps}-step run, wall time [s]", run_s, None),
            ("energy error, first tenth", first, TARGET_DRIFT),
            ("energy error, last tenth", last, TARGET_DRIFT)]
    for name, value, target in rows:
        met = "" if target is None else ("yes" if value < target else "NO")
        tgt = "" if target is None else f"{target:g}"
        print(f"{name:<38}{value:>12.4g}{tgt:>10}  {met}")
    print(f"(vibration energy E(0) − V(x_eq) = {scale:.4g}; largest kinetic energy "
          f"{float(ds['kinetic_energy'].max()):.4g}; tip swing "
          f"{np.ptp(ds['displacement'].values[:, np.argmax(body.reference[:, 1]), 0]):.3g})")
    out = xr.Dataset({
        "force_microseconds": ((), force_us, {"long_name": "median wall time of one internal-"
                                              "force evaluation", "units": "us"}),
        "step_microseconds_lumped": ((), step_us["lumped"], {
            "long_name": "median wall time of one explicit step, lumped mass", "units": "us"}),
        "step_microseconds_consistent": ((), step_us["consistent"], {
            "long_name": "median wall time of one explicit step, consistent mass",
            "units": "us"}),
        "run_seconds": ((), run_s, {"long_name": f"wall time of the {a.steps}-step solve",
                                    "units": "s"}),
        "energy_error_first_tenth": ((), first, {
            "long_name": "max |E − E(0)| / (E(0) − V(x_eq)) over the first tenth", "units": "1"}),
        "energy_error_last_tenth": ((), last, {
            "long_name": "max |E − E(0)| / (E(0) − V(x_eq)) over the last tenth", "units": "1"}),
        "critical_time_step": ((), float(ds["critical_time_step"]), {
            "long_name": "stability limit 2/ω_max", "units": "time"}),
        "n_steps": ((), a.steps, {"long_name": "time steps of the run", "units": "1"}),
        "n_nodes": ((), n_nodes, {"long_name": "mesh nodes", "units": "1"}),
        "n_triangles": ((), n_tri, {"long_name": "mesh triangles", "units": "1"}),
        "total_energy": (("time",), E, {"long_name": "total energy of the run",
                                        "units": "energy / length"})},
        coords={"time": ("time", ds["time"].values, {"long_name": "time", "units": "time"})},
        attrs={"title": "neo-Hookean explicit elastodynamics at the thesis size: speed and "
                        "energy error"})
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    out.to_netcdf(a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
