"""Speed of the axisymmetric Stokes boundary elements (issue 19 acceptance).

1. One solve of a 200-element generating curve (a squirmer: single-layer assembly, both
   dense LU factorisations, the double-layer right-hand side and the solves), median of
   ``--repeat`` runs after a warm-up. Target: under 0.5 s.
2. A 100-shape stroke at 200 elements (the small-amplitude stroke of
   experiments/small_amplitude_stroke.yaml at ε = 0.05: 101 samples, the last repeating the
   first, plus the drag solve of the mean shape). Target: under 1 minute.

Usage: python benchmarks/bench_stokes.py [out.nc] [--elements 200] [--shapes 100] [--repeat 5]
Writes benchmarks/results/bench_stokes.nc by default.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

TARGET_SOLVE, TARGET_STROKE = 0.5, 60.0


def main(argv=None):
    import xarray as xr

    from pointatlas_physics.stokes_axisymmetric.stroke import (Discretisation, solve_one,
                                                              swim_stroke)
    from pointatlas_studies import meridian_motions as mm

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", nargs="?", default=str(Path(__file__).parent / "results" /
                                                 "bench_stokes.nc"))
    p.add_argument("--elements", type=int, default=200)
    p.add_argument("--shapes", type=int, default=100)
    p.add_argument("--repeat", type=int, default=5)
    a = p.parse_args(argv)
    disc = Discretisation(n_elements=a.elements)
    nodes, v = mm.squirmer_slip(1.0, 257, 1.0, 0.7)
    solve_one(nodes, v, 1.0, Discretisation(n_elements=16))          # warm-up
    times = []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        s = solve_one(nodes, v, 1.0, disc)[1]
        times.append(time.perf_counter() - t0)
    solve_s = float(np.median(times))
    t, X, V = mm.small_amplitude_stroke(1.0, 257, a.shapes, 0.05, {2: 1.0, 3: 1j}, {})
    t0 = time.perf_counter()
    sol = swim_stroke(t, X, V, 1.0, disc)
    stroke_s = time.perf_counter() - t0
    rows = [("one solve", a.elements, solve_s, TARGET_SOLVE),
            (f"{a.shapes}-shape stroke", a.elements, stroke_s, TARGET_STROKE)]
    print(f"{'case':<20}{'elements':>9}{'seconds':>10}{'target':>8}  met")
    for name, n, sec, target in rows:
        print(f"{name:<20}{n:>9}{sec:>10.3f}{target:>8.1f}  {'yes' if sec < target else 'NO'}")
    print(f"(squirmer speed error {abs(s.translation / (2 / 3) - 1):.2e}; stroke net "
          f"displacement {sol.position[-1]:.6e})")
    ds = xr.Dataset({
        "solve_seconds": ((), solve_s, {"long_name": "median wall time of one solve",
                                        "units": "s"}),
        "stroke_seconds": ((), stroke_s, {"long_name": f"wall time of a {a.shapes}-shape "
                                          "stroke", "units": "s"}),
        "n_elements": ((), a.elements, {"long_name": "boundary elements", "units": "1"}),
        "n_shapes": ((), a.shapes, {"long_name": "shapes of the stroke", "units": "1"})},
        attrs={"title": "axisymmetric Stokes boundary elements: speed"})
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
