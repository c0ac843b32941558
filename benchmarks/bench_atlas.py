"""Time to build the atlas of a point-set sphere, stage by stage (issue 3 acceptance).

Atlas of a structured N-point sphere (source ``sphere``, rng seed 0) with the settings of
experiments/sphere_willmore.yaml: PCA embedder, LME γ = 0.8, tol 1e-10, Shepard PU γ = 4,
tol 1e-6, quadrature order 6, 150 markers per patch, least-squares fit of the control points.
Stages (as in the surface_geometry study): partition (METIS + recursive refinement + PU fit),
charts (embedding + LME + least-squares fit per patch), quadrature (Gauss points, ψ_κ, J_κ,
second derivatives). Wall and CPU seconds (all threads) are recorded per stage: CPU time is
less sensitive to other jobs sharing the cores. Numba is compiled beforehand by a warm-up on
a tiny sphere. Also reported: area, Willmore energy and total Gaussian curvature and their
relative errors against 4π, 16π and 4π.

Usage: python benchmarks/bench_atlas.py [out.nc] [--sizes 5000 10000 20000] [--repeat 1]
Writes benchmarks/results/bench_atlas.nc by default.
"""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

STAGES = ("partition", "charts", "quadrature")
TARGET_SECONDS = 60.0  # issue 3: 20 000 points in under a minute on 2 cores


def make_atlas():
    """An Atlas with the settings of experiments/sphere_willmore.yaml."""
    import pointatlas
    from pointatlas_atlas.atlas import Atlas
    from pointatlas_atlas.settings import AtlasSettings

    s = AtlasSettings(markers_per_patch=150, gamma_lme=0.8, tol_lme=1e-10, gamma_pu=4.0,
                      tol_pu=1e-6, quadrature_order=6, least_squares_fit=True)
    pca = pointatlas.load_plugin("embedders", "pca")
    lme = pointatlas.load_plugin("approximants", "lme")
    shepard = pointatlas.load_plugin("approximants", "shepard")
    return Atlas(s, make_embedder=lambda: pca(),
                 make_lme=lambda: lme(gamma=s.gamma_lme, tol=s.tol_lme, outside="flag"),
                 make_pu=lambda: shepard(gamma=s.gamma_pu, tol=s.tol_pu, outside="flag"))


def sphere(n: int):
    import pointatlas

    return pointatlas.load_plugin("sources", "sphere")(n_points=n).load(
        np.random.default_rng(0))


def build_timed(n: int) -> dict:
    """Build the atlas of an n-point sphere; wall/CPU seconds per stage and the integrals."""
    cloud = sphere(n)
    atlas = make_atlas()
    out = {}
    steps = {"partition": lambda: atlas.partition(cloud.points, cloud.markers),
             "charts": atlas.build_charts, "quadrature": atlas.build_quadrature}
    for stage in STAGES:
        t0, c0 = time.perf_counter(), time.process_time()
        steps[stage]()
        out[f"wall_{stage}"] = time.perf_counter() - t0
        out[f"cpu_{stage}"] = time.process_time() - c0
    qp = atlas.quadrature_points()
    g = qp.geometry
    out["area"] = float(np.sum(qp.weights))
    out["willmore_energy"] = float(np.sum(qp.weights * g["mean_curvature"] ** 2))
    out["total_gaussian_curvature"] = float(np.sum(qp.weights * g["gaussian_curvature"]))
    out["n_patches"] = len(atlas.charts_)
    out["n_quadrature_points"] = len(qp.weights)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=str(Path(__file__).parent / "results" /
                                                  "bench_atlas.nc"))
    ap.add_argument("--sizes", type=int, nargs="+", default=[5_000, 10_000, 20_000])
    ap.add_argument("--repeat", type=int, default=1, help="runs per size (best total kept)")
    args = ap.parse_args(argv)

    import xarray as xr

    build_timed(300)  # compile / load the numba caches
    rows = []
    for n in args.sizes:
        runs = [build_timed(n) for _ in range(args.repeat)]
        rows.append(min(runs, key=lambda r: sum(r[f"wall_{s}"] for s in STAGES)))
    exact = {"area": 4 * np.pi, "willmore_energy": 16 * np.pi,
             "total_gaussian_curvature": 4 * np.pi}
    load = os.getloadavg()[0]
    print(f"atlas benchmark: sphere, PCA charts, {os.cpu_count()} cores, "
          f"load average {load:.2f}; seconds wall / cpu")
    print(f"{'N':>7}{'patches':>8}" + "".join(f"{s:>18}" for s in STAGES + ("total",))
          + f"{'area err':>11}{'Willmore err':>13}")
    for n, r in zip(args.sizes, rows):
        cells = [f"{r[f'wall_{s}']:8.2f} / {r[f'cpu_{s}']:6.2f}" for s in STAGES]
        tw = sum(r[f"wall_{s}"] for s in STAGES)
        tc = sum(r[f"cpu_{s}"] for s in STAGES)
        cells.append(f"{tw:8.2f} / {tc:6.2f}")
        ea = abs(r["area"] - exact["area"]) / exact["area"]
        ew = abs(r["willmore_energy"] - exact["willmore_energy"]) / exact["willmore_energy"]
        print(f"{n:>7}{r['n_patches']:>8}" + "".join(f"{c:>18}" for c in cells)
              + f"{ea:>11.3e}{ew:>13.3e}")
    for n, r in zip(args.sizes, rows):
        print(f"N={n}: area {r['area']!r}  Willmore {r['willmore_energy']!r}  "
              f"∫K {r['total_gaussian_curvature']!r}")

    sec = {"units": "s"}
    data = {}
    for s in STAGES:
        data[f"wall_seconds_{s}"] = ("n_points", [r[f"wall_{s}"] for r in rows],
                                     {**sec, "long_name": f"wall time of the {s} stage"})
        data[f"cpu_seconds_{s}"] = ("n_points", [r[f"cpu_{s}"] for r in rows], {
            **sec, "long_name": f"CPU time (all threads) of the {s} stage"})
    data["wall_seconds_total"] = ("n_points", [sum(r[f"wall_{s}"] for s in STAGES)
                                               for r in rows],
                                  {**sec, "long_name": "wall time, partition+charts+quadrature"})
    data["cpu_seconds_total"] = ("n_points", [sum(r[f"cpu_{s}"] for s in STAGES)
                                              for r in rows],
                                 {**sec, "long_name": "CPU time, partition+charts+quadrature"})
    for key, units in (("area", "length^2"), ("willmore_energy", "1"),
                       ("total_gaussian_curvature", "1")):
        data[key] = ("n_points", [r[key] for r in rows],
                     {"units": units, "long_name": f"{key.replace('_', ' ')} of the atlas",
                      "reference": exact[key]})
        data[f"relative_error_{key}"] = (
            "n_points", [abs(r[key] - exact[key]) / exact[key] for r in rows],
            {"units": "1", "long_name": f"|computed − exact| / exact, {key.replace('_', ' ')}"})
    data["n_patches"] = ("n_points", [r["n_patches"] for r in rows],
                         {"units": "1", "long_name": "number of patches (charts)"})
    data["n_quadrature_points"] = ("n_points", [r["n_quadrature_points"] for r in rows],
                                   {"units": "1", "long_name": "quadrature points, all charts"})
    data["load_average"] = ((), load, {"units": "1", "long_name": "1-min load average at end"})
    ds = xr.Dataset(data, coords={"n_points": ("n_points", list(args.sizes), {
        "units": "1", "long_name": "points on the sphere"})},
        attrs={"title": "atlas build time of a point-set sphere (issue 3)",
               "settings": "PCA, LME gamma 0.8 tol 1e-10, Shepard gamma 4 tol 1e-6, "
                           "order 6, 150 markers/patch, least-squares fit",
               "cores": os.cpu_count(), "target_total_seconds_20000": TARGET_SECONDS})
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
