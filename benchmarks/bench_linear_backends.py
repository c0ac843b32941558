"""Benchmark: every linear-solver backend on the full hemisphere's constrained stiffness.

The matrix is the one the shell solves in bench_shell_hemisphere.py (same cloud, settings
and supports, about 9 000 DOF at 2 800 points): K_ρ = K + ρCᵀC with K the linear stiffness
plus ghost springs and ρ = penalty·mean diag K / mean diag CᵀC
(:class:`pointatlas_solvers.augmented_lagrangian.ConstrainedSystem`). For each backend of
:mod:`pointatlas_solvers.linear_backends` (SuperLU, PARDISO, AMG-preconditioned CG, and
ILU-preconditioned CG): the factorisation (or preconditioner set-up) time, one solve
K_ρ x = b with b = F + ρCᵀg, its relative residual, the whole augmented-Lagrangian solve
(what the shell runs: factorisation plus the multiplier iterations) and its difference to
SuperLU's answer, and the inertia the backend reports. A backend that is not installed or
fails is reported as such, with the time it took to fail. Times are the best of ``repeats``
runs (default 1).

Writes benchmarks/results/linear_backends.nc (or argv[1]).

Usage: .venv/bin/python benchmarks/bench_linear_backends.py [out.nc] [n_points] [repeats]
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import xarray as xr

from bench_shell_hemisphere import hemisphere_model, settings
from pointatlas_physics.kirchhoff_love.analysis import (assemble_loads, assemble_supports,
                                                         regularize_ghosts)
from pointatlas_physics.kirchhoff_love.linear import linear_stiffness
from pointatlas_solvers.augmented_lagrangian import solve_augmented
from pointatlas_solvers.linear_backends import BACKENDS, factorize, installed

NAN = float("nan")


def measure(backend, A, b, K, F, C, g, s, reference, repeats: int = 1):
    """One row: times (s, the best of ``repeats``; up to the failure if a stage fails),
    residual, difference to ``reference`` (U of SuperLU), pivots."""
    row = dict(factorize=NAN, solve=NAN, residual=NAN, constrained=NAN, iterations=-1,
               difference=NAN, negative_pivots=-2, cg_iterations=-1, note="ok")
    if not installed(backend):
        row["note"] = "not installed (pip install 'pointatlas[fast]')"
        return row, None
    stage, U = "factorize", None
    try:
        for _ in range(repeats):
            stage, t = "factorize", time.perf_counter()
            f = factorize(A, backend)
            row["factorize"] = np.fmin(row["factorize"], time.perf_counter() - t)
            row["negative_pivots"] = int(f.negative_pivots)
            stage, t = "solve", time.perf_counter()
            x = f.solve(b)
            row["solve"] = np.fmin(row["solve"], time.perf_counter() - t)
            row["residual"] = float(np.linalg.norm(A @ x - b) / np.linalg.norm(b))
            row["cg_iterations"] = int(getattr(f, "iterations", -1))
            del f
            stage, t = "constrained", time.perf_counter()
            U, _, info = solve_augmented(K, F, C, g, s.penalty, s.constraint_tol,
                                         backend=backend)
            row["constrained"] = np.fmin(row["constrained"], time.perf_counter() - t)
            row["iterations"] = int(info.iterations)
        if reference is not None:
            row["difference"] = float(np.abs(U - reference).max() / np.abs(reference).max())
        return row, U
    except Exception as exc:  # noqa: BLE001  (report the failure as a result)
        row[stage] = time.perf_counter() - t
        row["note"] = f"{type(exc).__name__} after {row[stage]:.1f} s in {stage}: {exc}"
        return row, None


def main(out: Path, n_points: int, repeats: int = 1) -> None:
    s = settings()
    model, _ = hemisphere_model(n_points, s)
    K = regularize_ghosts(linear_stiffness(model.quadrature, model.material), model)
    F = assemble_loads(model, s).ravel()
    cons = assemble_supports(model, s)
    C, g = cons.matrix, cons.rhs
    CtC = (C.T @ C).tocsr()
    rho = s.penalty * K.diagonal().mean() / CtC.diagonal().mean()
    A = (K + rho * CtC).tocsr()
    b = F + rho * (C.T @ g)
    print(f"full hemisphere: {model.points.shape[0]} points + {model.n_ghosts} ghosts = "
          f"{model.dof} DOF; K_ρ has {A.nnz} non-zeros, ρ = {rho:.3g}")
    rows, reference = {}, None
    for backend in BACKENDS:
        rows[backend], U = measure(backend, A, b, K, F, C, g, s, reference, repeats)
        if backend == "superlu":
            reference = U
            rows[backend]["difference"] = 0.0 if U is not None else NAN
    head = (f"{'backend':8s} {'factorize':>10s} {'solve':>8s} {'residual':>9s} "
            f"{'AL solve':>9s} {'AL it':>5s} {'vs superlu':>10s} {'neg. piv.':>9s}  note")
    print(head)
    for name, r in rows.items():
        print(f"{name:8s} {r['factorize']:9.2f}s {r['solve']:7.3f}s {r['residual']:9.1e} "
              f"{r['constrained']:8.2f}s {r['iterations']:5d} {r['difference']:10.1e} "
              f"{r['negative_pivots']:9d}  {r['note'][:90]}")
    names = list(rows)

    def var(key, long_name, units):
        return (("backend",), [rows[n][key] for n in names],
                {"long_name": long_name, "units": units})

    ds = xr.Dataset(
        {"factorize_time": var("factorize", "factorisation or preconditioner set-up of K_ρ",
                               "s"),
         "solve_time": var("solve", "one solve K_ρ x = b", "s"),
         "relative_residual": var("residual", "|K_ρ x − b| / |b| of that solve", "1"),
         "constrained_solve_time": var("constrained", "augmented-Lagrangian solve of "
                                       "K U = F subject to C U = g (factorisation included)",
                                       "s"),
         "constraint_iterations": var("iterations", "multiplier iterations of that solve",
                                      "1"),
         "difference_to_superlu": var("difference", "max |U − U_superlu| / max |U_superlu|",
                                      "1"),
         "negative_pivots": var("negative_pivots", "negative eigenvalues of K_ρ reported "
                                "by the backend (-1: no inertia, -2: not run)", "1"),
         "cg_iterations": var("cg_iterations", "CG iterations of the one solve (-1: direct)",
                              "1"),
         "dof": ((), model.dof, {"long_name": "degrees of freedom", "units": "1"}),
         "nonzeros": ((), A.nnz, {"long_name": "stored non-zeros of K_ρ", "units": "1"})},
        coords={"backend": ("backend", names, {"long_name": "linear-solver backend",
                                               "units": "1"})},
        attrs={"title": "linear-solver backends on the full hemisphere's K + ρCᵀC",
               "notes": "; ".join(f"{n}: {rows[n]['note']}" for n in names),
               "n_points": n_points, "repeats": repeats})
    out.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    here = Path(__file__).parent
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else here / "results/linear_backends.nc",
         int(sys.argv[2]) if len(sys.argv) > 2 else 2800,
         int(sys.argv[3]) if len(sys.argv) > 3 else 1)
