"""Benchmark: Kirchhoff–Love shell stiffness assembly (linear K and tangent K_T) vs problem size.

A doubly curved graph patch z = 0.3 (x² − 0.5 y²) over the unit square, LME basis (γ = 0.8,
tol = 1e-7: ≈ 60 nodes per point) on a jittered grid of N nodes, a 16-point Gauss rule
(order 6) on each Delaunay triangle (≈ 32 points per node), points grouped by 8×8 spatial
blocks (chart-like locality). Three sizes with points ∝ nodes; numba compile excluded (warm-up on a
tiny case). Prints a table and writes benchmarks/results/bench_shell_assembly.nc (or --out).

The shell energy goes through the physics kit's one assembler (pointatlas_kit.assembler).
With ``--old PATH`` (a checkout of the tree before the kit, e.g. ``git worktree add
/tmp/oldtree 27ba951``) the old hand-written shell assembler of PATH is timed on the same
points side by side, with the largest relative difference of the matrices.

Usage: .venv/bin/python benchmarks/bench_shell_assembly.py [--out out.nc] [--old PATH]
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numba
import numpy as np
import xarray as xr
from scipy.sparse import csr_matrix
from scipy.spatial import Delaunay

import pointatlas
from pointatlas_atlas.quadrature import map_rule_to_simplices, simplex_rule
from pointatlas_physics.kirchhoff_love.linear import linear_stiffness
from pointatlas_physics.kirchhoff_love.material import ShellMaterial
from pointatlas_physics.kirchhoff_love.nonlinear import internal_forces, tangent_stiffness
from pointatlas_kit.atlas_quadrature import AtlasQuadrature

SIDES = (29, 41, 58)  # nodes per side: ~840, ~1680, ~3360 nodes
MATERIAL = ShellMaterial(young_modulus=1.0e3, poisson_ratio=0.3, thickness=0.01)


def surface(p: np.ndarray) -> np.ndarray:
    return np.column_stack([p[:, 0], p[:, 1], 0.3 * (p[:, 0] ** 2 - 0.5 * p[:, 1] ** 2)])


def build_patch(side: int, order: int = 6, seed: int = 0):
    """AtlasQuadrature on a side×side jittered grid of the unit square (points sorted by block)."""
    g = np.linspace(0.0, 1.0, side)
    p = np.array(np.meshgrid(g, g, indexing="ij")).reshape(2, -1).T
    inner = np.all((p > 0) & (p < 1), axis=1)
    p[inner] += 0.2 / side * np.random.default_rng(seed).uniform(-1, 1, (inner.sum(), 2))
    lme = pointatlas.load_plugin("approximants", "lme")(gamma=0.8, tol=1e-7).fit(p)
    xi, wg = map_rule_to_simplices(p[Delaunay(p).simplices], simplex_rule(2, order))
    block = np.minimum((xi * 8).astype(int), 7)
    group = block[:, 0] * 8 + block[:, 1]
    o = np.lexsort((xi[:, 1], xi[:, 0], group))
    xi, wg, group = xi[o], wg[o], group[o]
    bf = lme.evaluate(xi, order=2)
    P = surface(p)
    n, m = len(P), len(xi)
    T = np.stack([bf.gradient_csr(n, k) @ P for k in range(2)], axis=1)
    S = np.empty((m, 2, 2, 3))
    for a in range(2):
        for b in range(2):
            S[:, a, b] = csr_matrix((bf.hessians[:, a, b], bf.indices, bf.indptr), (m, n)) @ P
    J = np.linalg.norm(np.cross(T[:, 0], T[:, 1]), axis=1)
    H = bf.hessians
    basis = np.column_stack([bf.values, bf.gradients[:, 0], bf.gradients[:, 1], H[:, 0, 0],
                             0.5 * (H[:, 0, 1] + H[:, 1, 0]), H[:, 1, 1]])
    return AtlasQuadrature(indptr=bf.indptr, indices=bf.indices, basis=basis, weights=wg * J,
                           chart=group, positions=bf.to_csr(n) @ P, tangents=T, second=S,
                           orientation=np.ones(m), n_nodes=n)


def load_old(root: Path):
    """The hand-written shell assembler of the tree at ``root`` (before the kit), as the
    package ``old_kirchhoff_love``: (linear K, tangent K_T, forces, ShellQuadrature maker)."""
    import importlib.util

    pkg = root / "plugins" / "physics" / "kirchhoff_love"
    spec = importlib.util.spec_from_file_location("old_kirchhoff_love", pkg / "__init__.py",
                                                  submodule_search_locations=[str(pkg)])
    mod = importlib.util.module_from_spec(spec)
    sys.modules["old_kirchhoff_love"] = mod
    spec.loader.exec_module(mod)
    import importlib

    lin = importlib.import_module("old_kirchhoff_love.linear").linear_stiffness
    nl = importlib.import_module("old_kirchhoff_love.nonlinear")
    sq = importlib.import_module("old_kirchhoff_love.quadrature_data").ShellQuadrature

    def convert(q):
        return sq(q.indptr, q.indices, q.basis, q.reference_jet(), q.weights, q.chart,
                  q.n_nodes)
    return lin, nl.tangent_stiffness, nl.internal_forces, convert


def timed(fn, *args):
    """(result, wall seconds); the CPU seconds of the call (all threads) go to CPU[-1]."""
    t, c = time.perf_counter(), time.process_time()
    out = fn(*args)
    CPU.append(time.process_time() - c)
    return out, time.perf_counter() - t


CPU: list[float] = []


def main(out_path: Path, old_root: Path | None = None) -> None:
    warm = build_patch(6, order=2)  # compile all kernels on a tiny case
    linear_stiffness(warm, MATERIAL)
    tangent_stiffness(warm, MATERIAL, np.zeros((warm.n_nodes, 3)))
    internal_forces(warm, MATERIAL, np.zeros((warm.n_nodes, 3)))
    old = load_old(old_root) if old_root else None
    if old:
        wq = old[3](warm)
        old[0](wq, MATERIAL), old[1](wq, MATERIAL, np.zeros((warm.n_nodes, 3)))
        old[2](wq, MATERIAL, np.zeros((warm.n_nodes, 3)))
    rows = []
    for side in SIDES:
        q, t_build = timed(build_patch, side)
        U = 0.01 * np.random.default_rng(1).standard_normal((q.n_nodes, 3))
        _, t_pattern = timed(q.assembly_plan)
        K, t_lin = timed(linear_stiffness, q, MATERIAL)
        c_lin = CPU[-1]
        KT, t_tan = timed(tangent_stiffness, q, MATERIAL, U)
        c_tan = CPU[-1]
        f, t_f = timed(internal_forces, q, MATERIAL, U)
        row = dict(nodes=q.n_nodes, points=q.n_points,
                   nodes_per_point=len(q.indices) / q.n_points, matrix_nnz=K.nnz,
                   build_s=t_build, pattern_s=t_pattern, linear_s=t_lin, tangent_s=t_tan,
                   linear_cpu_s=c_lin, tangent_cpu_s=c_tan, forces_s=t_f)
        if old:
            oq = old[3](q)
            oq.assembly_plan()
            K0, row["old_linear_s"] = timed(old[0], oq, MATERIAL)
            KT0, row["old_tangent_s"] = timed(old[1], oq, MATERIAL, U)
            f0, row["old_forces_s"] = timed(old[2], oq, MATERIAL, U)
            row["max_relative_difference"] = max(
                abs(K - K0).max() / abs(K0).max(), abs(KT - KT0).max() / abs(KT0).max(),
                float(np.abs(f - f0).max() / np.abs(f0).max()))
        rows.append(row)
    print(f"threads: {numba.get_num_threads()}   (wall s; 'cpu' = CPU s of all threads; per point "
          "in wall µs; linear/tangent include BSR→CSR; plan = pattern + blocks, once per q)")
    head = ("nodes", "points", "n/pt", "nnz(K)", "plan", "linear", "lin cpu", "tangent",
            "tan cpu", "forces", "lin µs/pt", "tan µs/pt")
    print(("{:>9} " * len(head)).format(*head))
    for r in rows:
        print(("{:>9d} {:>9d} {:>9.1f} {:>9d} {:>9.2f} {:>9.2f} {:>9.2f} {:>9.2f} {:>9.2f} "
               "{:>9.2f} {:>9.1f} {:>9.1f}").format(
                   r["nodes"], r["points"], r["nodes_per_point"], r["matrix_nnz"],
                   r["pattern_s"], r["linear_s"], r["linear_cpu_s"], r["tangent_s"],
                   r["tangent_cpu_s"], r["forces_s"], 1e6 * r["linear_s"] / r["points"],
                   1e6 * r["tangent_s"] / r["points"]))
    ds = xr.Dataset({k: ("size", np.array([r[k] for r in rows])) for k in rows[0]},
                    coords={"size": np.arange(len(rows))})
    ds["linear_us_per_point"] = 1e6 * ds.linear_s / ds.points
    ds["tangent_us_per_point"] = 1e6 * ds.tangent_s / ds.points
    ds.attrs.update(description="Kirchhoff-Love shell stiffness assembly times",
                    threads=numba.get_num_threads(), lme_gamma=0.8, lme_tol=1e-7,
                    gauss_order=6)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(out_path)
    if old:
        print("\nkit vs the old hand-written assembler (same points, µs per point, wall):")
        print(("{:>9} " * 8).format("points", "lin kit", "lin old", "ratio", "tan kit",
                                     "tan old", "ratio", "max rel"))
        for r in rows:
            lk, lo = 1e6 * r["linear_s"] / r["points"], 1e6 * r["old_linear_s"] / r["points"]
            tk, to = 1e6 * r["tangent_s"] / r["points"], 1e6 * r["old_tangent_s"] / r["points"]
            print("{:>9d} {:>9.1f} {:>9.1f} {:>9.2f} {:>9.1f} {:>9.1f} {:>9.2f} {:>9.1e}".format(
                r["points"], lk, lo, lk / lo, tk, to, tk / to, r["max_relative_difference"]))
        ds["old_linear_us_per_point"] = 1e6 * ds.old_linear_s / ds.points
        ds["old_tangent_us_per_point"] = 1e6 * ds.old_tangent_s / ds.points
        ds.to_netcdf(out_path)
    print(f"wrote {out_path}")


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "results"
                    / "bench_shell_assembly.nc")
    ap.add_argument("--old", type=Path, default=None)
    a = ap.parse_args()
    main(a.out, a.old)
