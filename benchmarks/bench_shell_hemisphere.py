"""Benchmark: linear pinched hemisphere, full model, point cloud to solved displacement.

Issue target: about 10 000 DOF in under 60 s on this machine, with the time split (boundary
and ghosts, partition, charts, quadrature, assembly, loads, supports, solve). The full
closed hemisphere (R = 10, h = 0.04, E = 6.825e7, ν = 0.3; thesis L1343) carries F = 2
outward at (±10, 0, 0) and inward at (0, ±10, 0); rigid motions are removed by holding the
pole's displacement and normal (by symmetry u = 0 relative to it and δn = 0 there) and u_y at
(10, 0, 0) (zero by symmetry), so the supports take no reaction.

The shell solves with ``physics.solver`` = argv[3] (default ``direct``, SuperLU; ``pardiso``
needs the extra ``fast``). It then solves the same constrained system with SuperLU and with
CG preconditioned by an incomplete LU and compares time and answer with the shell's solve
(every backend on this matrix: bench_linear_backends.py). Writes
benchmarks/results/bench_shell_hemisphere.nc (or argv[1]).

Usage: .venv/bin/python benchmarks/bench_shell_hemisphere.py [out.nc] [n_points] [solver]
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import xarray as xr

import pointatlas
from pointatlas_atlas.settings import AtlasSettings
from pointatlas_physics.kirchhoff_love.analysis import build_model, displacement_at, solve_linear
from pointatlas_kit.selectors import Selector
from pointatlas_physics.kirchhoff_love.settings import Load, ShellSettings, Support
from pointatlas_solvers.augmented_lagrangian import solve_augmented


def settings(solver: str = "direct") -> ShellSettings:
    def at(expr, boundary=True):
        return Selector(expression=expr, on_boundary=boundary)

    return ShellSettings(
        young_modulus=6.825e7, poisson_ratio=0.3, thickness=0.04, solver=solver,
        supports=[Support(kind="clamped", where=at("z > 9.9999", False)),
                  Support(kind="fixed", components=[1], where=at("x > 9.9999"))],
        loads=[Load(kind="point", at=[10, 0, 0], force=[2, 0, 0]),
               Load(kind="point", at=[-10, 0, 0], force=[-2, 0, 0]),
               Load(kind="point", at=[0, 10, 0], force=[0, -2, 0]),
               Load(kind="point", at=[0, -10, 0], force=[0, 2, 0])])


def hemisphere_model(n_points: int, s: ShellSettings):
    """(model, seconds to sample the cloud): boundary, ghosts, atlas and quadrature of the full
    hemisphere of ``n_points`` points (no stiffness yet)."""
    def make(family, name, **kw):
        return lambda: pointatlas.load_plugin(family, name)(**kw)

    a = AtlasSettings(markers_per_patch=100)
    t0 = time.perf_counter()
    cloud = pointatlas.load_plugin("sources", "hemisphere")(n_points=n_points).load(
        np.random.default_rng(0))
    t_source = time.perf_counter() - t0
    model = build_model(cloud, s, a, make("embedders", "pca", n_components=2),
                        make("approximants", "lme", gamma=a.gamma_lme, tol=a.tol_lme,
                             outside="flag"),
                        make("approximants", "shepard", gamma=a.gamma_pu, tol=a.tol_pu,
                             outside="flag"))
    return model, t_source


def main(out: Path, n_points: int, solver: str = "direct") -> None:
    s = settings(solver)
    t0 = time.perf_counter()
    model, t_source = hemisphere_model(n_points, s)
    solve_linear(model, s)
    total = time.perf_counter() - t0
    u, _ = displacement_at(model, [10, 0, 0])
    times = {"source": t_source, **model.times}
    print(f"full hemisphere: {model.points.shape[0]} points + {model.n_ghosts} ghosts = "
          f"{model.dof} DOF, {len(model.atlas.charts_)} patches, "
          f"{len(model.quadrature.weights)} quadrature points")
    print(f"radial displacement at (10,0,0): {u[0]:.6f} (ref 0.0924, rel. error "
          f"{abs(u[0] - 0.0924) / 0.0924:.2e})")
    print(f"point cloud -> displacement: {total:.1f} s (physics.solver={solver})")
    for k, v in times.items():
        print(f"  {k:12s} {v:7.2f} s")
    K = model.stiffness
    F = model.forces.ravel()
    C, g = model.constraints.matrix, model.constraints.rhs
    rows = []
    for method in ("superlu", "cg_ilu"):
        t = time.perf_counter()
        try:
            U, _, info = solve_augmented(K, F, C, g, s.penalty, s.constraint_tol, backend=method)
            dt = time.perf_counter() - t
            diff = float(np.abs(U - model.nodal_displacement.ravel()).max()
                         / np.abs(model.nodal_displacement).max())
            note = "ok"
        except Exception as exc:  # noqa: BLE001  (report the failure as a result)
            dt, diff, note = time.perf_counter() - t, float("nan"), str(exc)[:80]
        rows.append((method, dt, diff, note))
        print(f"solver {method:7s}: {dt:7.2f} s, max rel. difference to the shell's solve "
              f"{diff:.1e} {note}")
    ds = xr.Dataset(
        {"time": (("stage",), list(times.values()), {"long_name": "wall time per stage",
                                                     "units": "s"}),
         "solver_time": (("solver",), [r[1] for r in rows], {"long_name": "constrained solve",
                                                             "units": "s"}),
         "solver_difference": (("solver",), [r[2] for r in rows], {
             "long_name": "max |U − U_shell| / max |U_shell| (U_shell: the shell's solve)",
             "units": "1"}),
         "total_time": ((), total, {"long_name": "point cloud to displacement", "units": "s"}),
         "dof": ((), model.dof, {"long_name": "degrees of freedom", "units": "1"}),
         "displacement": ((), float(u[0]), {"long_name": "radial displacement at (10, 0, 0)",
                                            "units": "length", "reference": 0.0924})},
        coords={"stage": ("stage", list(times), {"long_name": "stage", "units": "1"}),
                "solver": ("solver", [r[0] for r in rows], {"long_name": "solver",
                                                            "units": "1"})},
        attrs={"title": "linear pinched hemisphere, full model", "physics_solver": solver,
               "notes": "; ".join(f"{r[0]}: {r[3]}" for r in rows)})
    out.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    here = Path(__file__).parent
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else here / "results/bench_shell_hemisphere.nc",
         int(sys.argv[2]) if len(sys.argv) > 2 else 2800,
         sys.argv[3] if len(sys.argv) > 3 else "direct")
