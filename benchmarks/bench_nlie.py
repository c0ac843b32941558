"""Benchmark: NLIE on swiss rolls of 5k, 10k, 20k points (k_G = 200, d = 2).

Each size runs in a fresh subprocess so that its peak RSS (``ru_maxrss``) is its own. Prints a
table (N, seconds, peak RSS MiB, L-BFGS / Newton / CG iterations, stress per pair E_S / (12 N)
over the 12 geodesically nearest neighbours, converged, 1-minute load average at the end; the
machine may be shared) 
and writes ``results/bench_nlie.nc`` beside this script (or to argv[1]).
Usage: python benchmarks/bench_nlie.py [out.nc] [N ...]
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

K_G = 200


def swiss_roll(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = 1.5 * np.pi * (1 + 2 * rng.random(n))
    h = 21 * rng.random(n)
    return np.c_[t * np.cos(t), h, t * np.sin(t)]


def run_one(n: int) -> dict:
    import os
    import resource
    import time

    import numba

    from pointatlas_embedders.nlie import NLIE

    NLIE(n_stress_neighbors=20).fit(swiss_roll(300, seed=1))   # numba compile, not timed
    X = swiss_roll(n)
    t0 = time.perf_counter()
    m = NLIE(n_components=2, n_neighbors=12, n_stress_neighbors=K_G, alpha=0.99).fit(X)
    dt = time.perf_counter() - t0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return {"n": n, "seconds": dt, "peak_rss_mib": rss, "lbfgs_iter": m.info_["lbfgs_iter"],
            "newton_iter": m.info_["newton_iter"], "cg_iter": m.info_["cg_iter"],
            "newton_convex_steps": m.info_["newton_convex_steps"],
            "objective": m.objective_, "stress_k12": m.stress_,
            "grad_max_over_tol": m.info_["grad_max"] / m.info_["grad_tol"],
            "converged": bool(m.converged_), "numba_threads": numba.get_num_threads(),
            "load_avg_1min": os.getloadavg()[0]}


def main(argv: list[str]) -> None:
    if argv and argv[0] == "--one":
        print(json.dumps(run_one(int(argv[1]))))
        return
    import xarray as xr

    out = Path(argv[0]) if argv and argv[0].endswith(".nc") else Path(__file__).parent / "results" / "bench_nlie.nc"
    sizes = [int(a) for a in argv if a.isdigit()] or [5000, 10000, 20000]
    rows = []
    print(f"{'N':>7} {'time [s]':>9} {'peak RSS [MiB]':>15} {'L-BFGS':>7} {'Newton':>7} {'CG':>6} "
          f"{'E_S/pair':>10} {'conv':>5} {'load':>5}")
    for n in sizes:
        res = subprocess.run([sys.executable, __file__, "--one", str(n)], capture_output=True,
                             text=True, check=True)
        r = json.loads(res.stdout.strip().splitlines()[-1])
        rows.append(r)
        print(f"{n:>7} {r['seconds']:>9.1f} {r['peak_rss_mib']:>15.0f} {r['lbfgs_iter']:>7} "
              f"{r['newton_iter']:>7} {r['cg_iter']:>6} {r['stress_k12'] / (12 * n):>10.2e} "
              f"{str(r['converged']):>5} {r['load_avg_1min']:>5.1f}", flush=True)
    keys = ["seconds", "peak_rss_mib", "lbfgs_iter", "newton_iter", "newton_convex_steps",
            "cg_iter", "objective", "stress_k12", "grad_max_over_tol", "converged",
            "numba_threads", "load_avg_1min"]
    ds = xr.Dataset({k: ("n_points", np.array([r[k] for r in rows], dtype=float)) for k in keys},
                    coords={"n_points": [r["n"] for r in rows]},
                    attrs={"data": "swiss roll t ~ U(1.5pi, 4.5pi), h ~ U(0, 21)",
                           "n_stress_neighbors": K_G, "n_neighbors": 12, "alpha": 0.99,
                           "n_components": 2})
    ds.to_netcdf(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv[1:])
