"""Atlas of the 3-sphere S^3 ⊂ R^4 (d = 3 charts): volume and curvature integrals vs N.

Issue 3 asks the atlas to work for d = 1, 2, 3. This study shows the errors decreasing
with the number of points, and why d = 3 charts need a wider chart margin than surfaces
(AtlasSettings.margin_for): an LME chart maps the neighbourhood of the convex hull of its
control points onto chords (Paper 1 §2.3), and the hull of scattered points in d = 3 is
ragged, so with a 3h margin part of the quadrature weight sits on chords inside the sphere.

Set-up: ``hypersphere`` source (radius 1, random sampling, seed 0), PCA charts, LME γ 0.8,
Shepard PU γ 4, 30 markers per patch, no re-partition (max_refinement_depth 0, loose chart
test: PCA caps of S^3 are accepted as they are), quadrature order 2 (order 1 does not
converge: ψ_κ varies on the scale of the tetrahedra). Reported per (margin, N): relative
errors of the volume 2π², of ∫R dV (scalar curvature R = 6) and of ∫H² dV (H = mean
curvature of the hypersurface, |H| = 3 with H = κ1+κ2+κ3), the weight share of quadrature
points more than 5 % off the sphere, the number of quadrature points and the wall time.

With exact LME Hessians the curvature integrals do not converge (the samples are not
lattice-like, README "Known limits"); ``--chart-hessians consistent --no-fit`` gives
second-order consistent Hessians on unfitted control points, whose curvature integrals do;
``--chart-reproduction quartic --no-fit`` (charts that are quartic least-squares fits on the
LME support) is far more accurate (2 000 points: ∫R dV −1.1 %, against −10 % exact and
+5.0 % consistent) and far slower (35-monomial fits: 31 min at 2 000 points).

Usage: python benchmarks/three_sphere_convergence.py [out.nc] [--sizes 2000 4000 8000]
       [--margins 3 default] [--chart-hessians exact|consistent] [--no-fit]
       [--chart-reproduction linear|quadratic|cubic|quartic]
Writes benchmarks/results/three_sphere_convergence.nc by default.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np


def build(n: int, margin, hessians: str = "exact", fit: bool = True,
          reproduction: str = "linear"):
    import pointatlas
    from pointatlas_atlas.atlas import Atlas
    from pointatlas_atlas.settings import AtlasSettings

    s = AtlasSettings(markers_per_patch=30, max_refinement_depth=0, chart_margin=margin,
                      quadrature_order=2, max_stress=0.08, max_distortion=20.0,
                      chart_hessians=hessians, least_squares_fit=fit,
                      chart_reproduction=reproduction)
    pca = pointatlas.load_plugin("embedders", "pca")
    lme = pointatlas.load_plugin("approximants", "lme")
    shepard = pointatlas.load_plugin("approximants", "shepard")
    atlas = Atlas(s, make_embedder=lambda: pca(n_components=3),
                  make_lme=lambda: lme(gamma=s.gamma_lme, tol=s.tol_lme, outside="flag",
                                       hessians=s.chart_hessians,
                                       reproduction=s.chart_reproduction),
                  make_pu=lambda: shepard(gamma=s.gamma_pu, tol=s.tol_pu, outside="flag"))
    cloud = pointatlas.load_plugin("sources", "hypersphere")(n_points=n, radius=1.0).load(
        np.random.default_rng(0))
    t0 = time.perf_counter()
    atlas.build(cloud.points)
    q = atlas.quadrature_points()
    seconds = time.perf_counter() - t0
    e = cloud.exact
    radius = np.linalg.norm(q.positions, axis=1)
    off = np.abs(radius - 1.0) > 0.05
    vol = float(np.sum(q.weights))
    scal = float(np.sum(q.weights * q.geometry["scalar_curvature"]))
    h2 = float(np.sum(q.weights * q.geometry["mean_curvature"] ** 2))
    return {
        "volume_error": vol / e["volume"] - 1.0,
        "scalar_curvature_error": scal / e["total_scalar_curvature"] - 1.0,
        "mean_curvature_squared_error": h2 / e["mean_curvature_squared_integral"] - 1.0,
        "off_sphere_weight_share": float(q.weights[off].sum() / q.weights.sum()),
        "n_quadrature_points": float(len(q.weights)),
        "n_patches": float(len(atlas.charts_)),
        "margin": float(atlas.settings.margin_for(3)),
        "build_seconds": seconds,
    }


UNITS = {"volume_error": "1", "scalar_curvature_error": "1",
         "mean_curvature_squared_error": "1", "off_sphere_weight_share": "1",
         "n_quadrature_points": "1", "n_patches": "1", "margin": "median point spacing",
         "build_seconds": "s"}


def main(argv=None):
    import xarray as xr

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=str(Path(__file__).parent / "results"
                                                  / "three_sphere_convergence.nc"))
    ap.add_argument("--sizes", type=int, nargs="+", default=[2000, 4000, 8000])
    ap.add_argument("--margins", nargs="+", default=["3", "default"])
    ap.add_argument("--chart-hessians", default="exact", choices=["exact", "consistent"],
                    help="LME Hessians of the charts (consistent: exact for quadratics)")
    ap.add_argument("--chart-reproduction", default="linear",
                    choices=["linear", "quadratic", "cubic", "quartic"],
                    help="charts Σ p_a P_a (linear) or the polynomial fit of that degree")
    ap.add_argument("--no-fit", action="store_true",
                    help="no least-squares fit of the control points")
    args = ap.parse_args(argv)
    build(300, None)  # compile the numba kernels outside the timings
    rows = {}
    print(f"{'margin':>8} {'N':>6} {'volume':>10} {'∫R':>10} {'∫H²':>10} {'off>5%':>9} "
          f"{'n_quad':>9} {'s':>7}")
    for m in args.margins:
        margin = None if m == "default" else float(m)
        for n in args.sizes:
            r = build(n, margin, args.chart_hessians, not args.no_fit,
                      args.chart_reproduction)
            rows[(m, n)] = r
            print(f"{m:>8} {n:6d} {r['volume_error']:10.2e} {r['scalar_curvature_error']:10.2e} "
                  f"{r['mean_curvature_squared_error']:10.2e} "
                  f"{r['off_sphere_weight_share']:9.2e} {int(r['n_quadrature_points']):9d} "
                  f"{r['build_seconds']:7.1f}", flush=True)
    data = {k: (("margin_setting", "n_points"),
                np.array([[rows[(m, n)][k] for n in args.sizes] for m in args.margins]),
                {"units": UNITS[k], "long_name": k.replace("_", " ")})
            for k in UNITS}
    ds = xr.Dataset(data, coords={"margin_setting": list(args.margins),
                                  "n_points": ("n_points", args.sizes, {"units": "1"})},
                    attrs={"title": "S^3 atlas convergence (benchmarks/three_sphere_convergence.py)",
                           "chart_hessians": args.chart_hessians,
                           "chart_reproduction": args.chart_reproduction,
                           "least_squares_fit": int(not args.no_fit)})
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(out.name + ".tmp")
    ds.to_netcdf(tmp)
    tmp.replace(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
