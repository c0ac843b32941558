"""Benchmark: pointatlas Isomap vs scikit-learn Isomap on a swiss roll (numpy-generated).

Prints a table (N, time ours, time sklearn, max |difference| after sign alignment, relative to
max |Y|) and writes ``results/bench_isomap.nc`` beside this script (or to argv[1]).
Usage: python benchmarks/bench_isomap.py [out.nc] [N ...]
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import xarray as xr


def swiss_roll(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = 1.5 * np.pi * (1 + 2 * rng.random(n))
    h = 21 * rng.random(n)
    return np.c_[t * np.cos(t), h, t * np.sin(t)]


def main(argv: list[str]) -> None:
    from sklearn.manifold import Isomap as SkIsomap

    from pointatlas_embedders.isomap import Isomap

    out = Path(argv[0]) if argv and argv[0].endswith(".nc") else Path(__file__).parent / "results" / "bench_isomap.nc"
    sizes = [int(a) for a in argv if a.isdigit()] or [2000, 5000, 10000]
    k, d = 12, 2
    Isomap(n_neighbors=k, n_components=d).fit_transform(swiss_roll(300))  # warm-up (numba, imports)
    rows = []
    print(f"{'N':>7} {'ours [s]':>9} {'sklearn [s]':>11} {'max|dY|':>10} {'rel':>9}")
    for n in sizes:
        X = swiss_roll(n)
        t0 = time.perf_counter()
        Y = Isomap(n_neighbors=k, n_components=d).fit_transform(X)
        t_ours = time.perf_counter() - t0
        t0 = time.perf_counter()
        Ys = SkIsomap(n_neighbors=k, n_components=d).fit_transform(X)
        t_sk = time.perf_counter() - t0
        sign = np.sign(np.sum(Y * Ys, axis=0))
        diff = float(np.abs(Y * sign - Ys).max())
        rel = diff / float(np.abs(Ys).max())
        rows.append((n, t_ours, t_sk, diff, rel))
        print(f"{n:>7} {t_ours:>9.2f} {t_sk:>11.2f} {diff:>10.2e} {rel:>9.1e}")
    a = np.array(rows)
    ds = xr.Dataset(
        {"time_pointatlas": ("n_points", a[:, 1], {"units": "s"}),
         "time_sklearn": ("n_points", a[:, 2], {"units": "s"}),
         "max_abs_diff": ("n_points", a[:, 3]),
         "rel_diff": ("n_points", a[:, 4])},
        coords={"n_points": a[:, 0].astype(int)},
        attrs={"data": "swiss roll, t ~ U(1.5pi, 4.5pi), h ~ U(0, 21)", "n_neighbors": k,
               "n_components": d})
    ds.to_netcdf(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv[1:])
