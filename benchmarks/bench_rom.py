"""Speed of the reduced model of a 2-D neo-Hookean body against the full one (issue 21).

1. Full model: the ``neo_hookean_2d`` physics plugin at the thesis size (``n_triangles`` 9428,
   4 945 nodes), lumped mass, Δt = 2·10⁻⁵, integrated by ``physics.solve`` from rest in the
   reference configuration (the column sags under gravity). µs per step = wall / n_steps
   after a warm-up solve; wall time per simulated second = µs per step / Δt.
2. Reduced model on a two-dimensional slow manifold of about 2 000 LME nodes (γ = 0.8). The
   manifold is synthetic but mechanical: with φ₁ … φ₄ the four lowest vibration modes of the
   column about its reference (K_ff φ = ω² M_ff φ, lumped M), the snapshots are

       x(q) = X + c₁ q₁ φ₁ + c₂ q₂ φ₂ − c₄ (q₁² + q₂²) φ₄ + c₃ q₁ q₂ φ₃,

   q uniform in the unit disc: two bending modes (tip swing 0.15 and 0.05 at |q| = 1, the
   column is 1.5 high), the shortening that goes with bending (along the axial mode φ₄, tip
   drop 0.01) and a coupling. The embedding is q itself (PCA would give the same chart up to
   a rotation, at the cost of a full SVD of the 20 000 × 9 890 snapshot matrix). The
   reduced Lagrangian is tabulated on a 129 × 129 grid over the disc's box (``Table2D.
   from_batch``; grid points outside the LME nodes' hull are invalid and not evaluated) and
   integrated by ``integrate_table_2d`` with Δt = 10⁻⁴. The untabulated reduced model
   (``variational_integrator.integrate`` on ``ReducedLagrangian.terms``: an LME evaluation
   and a full-mesh energy and force per call) is timed over 200 steps.
   Speed-up = full wall time per simulated second / reduced wall time per simulated second.
3. NLIE (d = 2, k_G = 200, α = 0.99) on training sets of N snapshots of the same family,
   pruned to the boundary landmark nodes (clamped nodes excluded).

Measured on this machine (2 cores, numba threads 2, OpenMP layer), ``MPLBACKEND=Agg python
benchmarks/bench_rom.py`` (about 6 min in all, peak RSS 5.2 GB), 2026-12-05:

    full model, 4 945 nodes, Δt 2e-5    197 µs / step      9.87 s wall per simulated s
    manifold: 20 000 snapshots, n_bins 49 → 2 035 LME nodes, fit 42 s, residual 5.8e-5
    table 129 × 129: built in 65 s, table_error 2.35e-3 (M̃; Ṽ 1.2e-5), 77 % cells usable
    reduced, tabulated, Δt 1e-4        0.121 µs / step    1.21e-3 s per simulated s   8 130×
    reduced, direct, Δt 1e-4           9 020 µs / step    90.2 s per simulated s      0.11×
    NLIE, D = 898 (449 landmarks)      N 5 000: 15.0 s, 10 000: 48.0 s, 20 000: 98.1 s
    (--large, run alone earlier: N 50 000: 493 s, not converged, grad_max / tol = 160)

NLIE again on 2026-12-07, after the Euclidean steps were made dimension-proof (duplicates by
sorting, pruned farthest-point sampling, exact edge lengths), same sets:

    NLIE, D = 898 (449 landmarks)      N 5 000: 5.0 s, 10 000: 19.8 s, 20 000: 35.4 s
    (--large: N 50 000: 213 s, converged in 18 Newton iterations, grad_max / tol = 0.0013)

Later that day: the k-NN graph through a projection (``projected_knn``: exact, 1.9–2.8 s at
20 000 against 12–13 s), the family built from a fixed ARPACK start and sign (it had been
random, and so were NLIE's iteration counts: 11–15 at 20 000), and Newton's approximate
Wolfe steps at the round-off floor (50 000 had stopped at 3.4× its gradient tolerance):

    NLIE, D = 898 (449 landmarks)      N 5 000: 6.2 s (12 Newton iterations),
                                       10 000: 22.4–25.8 s (33), 20 000: 24.1–30.4 s (14)
    (--large: N 50 000: 188.5 s, converged in 29 Newton iterations, grad_max / tol = 0.15)
    house swiss roll, same session     N 20 000: 35.4–38.2 s (stored 21.9 s, another day)

The tabulated reduced model meets the 100× target by almost two orders of magnitude. The
direct one (an LME evaluation of 2 035 nodes with second derivatives, D²X of the full mesh and
a full-mesh energy and force, twice per step: the step and the saved energy) is 9× slower than
the full model; before single points ran on one numba thread (``support.threads_for``) the
thread team's wake-up made it 57 ms per step. The reduced dynamics (modes at 4.8 and
19 rad/s) is sensitive: round-off in the fit changes max |q| between 0.37 and 0.47 from run to
run, but the energy confines it inside the disc. NLIE was 4.5–7× slower than the house
NLIE reference (swiss roll, D = 3, benchmarks/results/bench_nlie.nc: 20 000 points in
21.9 s): with D = 898 the Euclidean steps dominated (at N = 50 000: farthest-point sampling
of the landmark-Isomap seed 183 s, check_distinct 93 s, k-NN graph 89 s, Newton 97 s). Now
(N = 20 000): k-NN graph 11 s (scikit-learn's brute search, BLAS-bound: a ball tree is no
faster here and 50× slower on full-rank data), farthest points 0.55 s, duplicates 1.0 s,
the Newton stage 21 s (the swiss roll's, D-independent), landmark geodesics 9 s.

Usage: python benchmarks/bench_rom.py [--quick] [--large] [--full-steps N] [--rom-steps N]
``--quick``: 2 000 triangles, NLIE at N = 2 000 only (a smoke check, well under a minute).
``--large``: NLIE also at N = 50 000 (slow).
"""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

DT_FULL, DT_ROM = 2e-5, 1e-4
TARGET_SPEEDUP = 100.0
SNAPSHOT_SEED = 0


def _context(n_triangles, n_steps):
    from pointatlas.context import RunContext

    return RunContext(config={"physics": {"n_triangles": n_triangles, "n_steps": n_steps,
                                          "save_every": n_steps}},
                      choices={"physics": "neo_hookean_2d"}, seed=0)


def time_full(n_triangles, n_steps):
    """(µs per step, wall of the timed solve [s], warm-up solve of 10 steps [s], n_nodes)."""
    ctx = _context(n_triangles, n_steps)
    phys = ctx.plugin("physics")
    t0 = time.perf_counter()
    phys.solve(ctx, n_steps=10)                         # numba compile / cache load
    warm = time.perf_counter() - t0
    t0 = time.perf_counter()
    ds = phys.solve(ctx)
    wall = time.perf_counter() - t0
    if int(ds["time"].size) < 2 or not np.all(np.isfinite(ds["total_energy"].values)):
        raise RuntimeError("the full solve did not produce a finite trajectory")
    return wall / n_steps * 1e6, wall, warm, int(ds["node"].size)


class Family:
    """The synthetic two-parameter family x(q) of the module doc, on a body."""

    def __init__(self, body):
        from scipy.sparse import diags
        from scipy.sparse.linalg import eigsh

        free = body.free_dofs
        K = body.tangent(body.reference)[free][:, free].tocsc()
        m = np.repeat(body.nodal_masses, 2)
        # a fixed start vector and sign (ARPACK's default start is random: the family, and so
        # the timings of the embedders on it, changed from process to process)
        w2, vec = eigsh(K, k=4, M=diags(m[free]).tocsc(), sigma=0, which="LM",
                        v0=np.ones(K.shape[0]))
        vec *= np.sign(vec[np.argmax(np.abs(vec), axis=0), np.arange(vec.shape[1])])
        order = np.argsort(w2)
        self.omega = np.sqrt(w2[order])
        phi = np.zeros((2 * body.mesh.n_nodes, 4))
        phi[free] = vec[:, order]
        top = int(np.argmax(body.reference[:, 1]))
        tip = phi.reshape(-1, 2, 4)[top]                 # (2, 4): tip displacement per mode
        # scale so the tip moves by the amounts of the module doc at |q| = 1; the axial
        # mode's sign so that the quadratic term shortens the column
        amp = np.array([0.15, 0.05, 0.01, 0.01]) / np.abs(tip).max(axis=0)
        amp[3] *= -np.sign(tip[1, 3])
        self.basis = phi * amp                           # (D, 4) columns: φ₁ φ₂ φ₃ φ₄ scaled
        self.reference = body.reference.ravel().copy()

    @staticmethod
    def coefficients(Q):
        q1, q2 = Q[:, 0], Q[:, 1]
        return np.column_stack([q1, q2, q1 * q2, q1 * q1 + q2 * q2])

    def snapshots(self, Q, columns=None):
        """x(q) (N, D), or only the given columns of it."""
        B = self.basis if columns is None else self.basis[columns]
        X0 = self.reference if columns is None else self.reference[columns]
        out = self.coefficients(Q) @ B.T
        out += X0
        return out


def disc(n, seed):
    """n points uniform in the unit disc."""
    rng = np.random.default_rng(seed)
    r, t = np.sqrt(rng.random(n)), 2 * np.pi * rng.random(n)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def bins_for(Q, n_nodes):
    """The ``n_bins`` whose bin means plus hull vertices come closest to ``n_nodes`` nodes."""
    from pointatlas_reduction.slow_manifold import binned_nodes, hull_vertices

    hull = hull_vertices(Q)

    def count(nb):
        return len(np.unique(np.concatenate([binned_nodes(Q, nb), hull]), axis=0))
    return min(range(4, 200), key=lambda nb: abs(count(nb) - n_nodes))


def terms_batch(sm, body, mass, chunk=256):
    """``Table2D.from_batch``'s terms_batch of the reduced Lagrangian (the formulas of
    :mod:`pointatlas_reduction.reduced_lagrangian`, vectorised over points): a point is valid
    when it lies inside the LME nodes' hull and no triangle is inverted there."""
    def batch(Q):
        m = len(Q)
        M, dM = np.full((m, 2, 2), np.nan), np.full((m, 2, 2, 2), np.nan)
        V, F = np.full(m, np.nan), np.full((m, 2), np.nan)
        outside = sm.basis_.evaluate(Q, order=0).outside
        inside = np.flatnonzero(np.ones(m, bool) if outside is None else ~outside)
        for s in range(0, len(inside), chunk):
            idx = inside[s:s + chunk]
            X, DX, D2X = sm.evaluate(Q[idx], order=2)
            MJ = mass[None, :, None] * DX
            M[idx] = np.einsum("mDi,mDj->mij", DX, MJ)
            dm = np.einsum("mDik,mDj->mijk", D2X, MJ)
            dM[idx] = dm + dm.transpose(0, 2, 1, 3)
            for j, k in enumerate(idx):
                xn = X[j].reshape(-1, 2)
                V[k] = body.potential_energy(xn)
                F[k] = DX[j].T @ body.forces(xn).ravel()
        valid = np.isfinite(V) & np.isfinite(F).all(axis=1)
        return valid, M, dM, V, F
    return batch


def time_reduced(body, n_snapshots, n_nodes, grid, rom_steps):
    """The slow manifold, its table and the timings of the reduced models (a dict)."""
    from pointatlas.context import RunContext
    from pointatlas_reduction.reduced_lagrangian import ReducedLagrangian
    from pointatlas_reduction.slow_manifold import SlowManifold
    from pointatlas_reduction.tabulated_2d import Table2D, integrate_table_2d
    from pointatlas_reduction.variational_integrator import integrate

    r = {}
    ctx = RunContext(config={}, choices={}, seed=0)
    t0 = time.perf_counter()
    family = Family(body)
    Q = disc(n_snapshots, SNAPSHOT_SEED)
    X = family.snapshots(Q)
    r["snapshots_s"] = time.perf_counter() - t0
    nb = bins_for(Q, n_nodes)
    t0 = time.perf_counter()
    sm = SlowManifold(ctx.make("approximant", "lme", gamma=0.8), n_bins=nb).fit(X, Q)
    r["fit_s"] = time.perf_counter() - t0
    del X
    r.update(n_bins=nb, n_nodes=len(sm.nodes_), residual=sm.residual_,
             n_unfitted=sm.n_unfitted_, omega=family.omega)
    mass = np.repeat(body.nodal_masses, 2)
    mass[np.repeat(body.clamped, 2)] = 0.0

    def potential(x):
        xn = x.reshape(-1, 2)
        return body.potential_energy(xn), -body.forces(xn).ravel()
    RL = ReducedLagrangian(sm, mass, potential)
    batch = terms_batch(sm, body, mass)
    probe = np.array([[0.1, -0.2], [-0.5, 0.3], [0.0, 0.0]])    # the batch = RL.terms
    ok, M, dM, V, F = batch(probe)
    for i, q in enumerate(probe):
        T = RL.terms(q)
        for a, b in ((M[i], T.mass), (dM[i], T.mass_derivative), (V[i], T.potential),
                     (F[i], T.force)):
            np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12 * np.abs(b).max())
    lo, hi = Q.min(axis=0), Q.max(axis=0)
    t0 = time.perf_counter()
    table = Table2D.from_batch(batch, lo, hi, n=(grid, grid))
    r["table_s"] = time.perf_counter() - t0
    r.update(table_error=table.table_error, mass_error=table.mass_error,
             potential_error=table.potential_error, usable=float(table.usable.mean()))

    q0, v0 = np.array([0.3, 0.2]), np.array([0.5, -0.5])
    T0 = table.terms(q0)
    E0 = 0.5 * v0 @ T0.mass @ v0 + T0.potential
    g = np.stack(np.meshgrid(table.x, table.y, indexing="ij"), -1).reshape(-1, 2)
    well = table.evaluate(g)[:, 0, 0] <= E0                  # grid points with Ṽ ≤ E₀
    r["confined"] = float(np.hypot(*g[well].T).max() + np.hypot(*table.h))
    integrate_table_2d(table, q0, v0, DT_ROM, 10)                # numba compile
    t0 = time.perf_counter()
    T, Qt, P, E, _ = integrate_table_2d(table, q0, v0, DT_ROM, rom_steps,
                                        save_every=max(1, rom_steps // 1000))
    wall = time.perf_counter() - t0
    r.update(table_us=wall / rom_steps * 1e6, table_wall=wall, rom_steps=rom_steps,
             rom_radius=float(np.hypot(Qt[:, 0], Qt[:, 1]).max()),
             rom_energy_drift=float(np.ptp(E) / max(abs(E[0]), 1e-300)))
    n_direct = 200
    integrate(RL.terms, q0, v0, DT_ROM, 2)                       # warm-up
    t0 = time.perf_counter()
    integrate(RL.terms, q0, v0, DT_ROM, n_direct)
    r["direct_us"] = (time.perf_counter() - t0) / n_direct * 1e6
    return r


def time_nlie(body, sizes):
    """(landmark nodes, {N: (seconds, Newton iterations, grad_max / grad_tol, converged)})
    of NLIE on boundary-landmark snapshots of the family."""
    from pointatlas.context import RunContext
    from pointatlas_reduction.training_set import boundary_nodes, landmark_columns

    ctx = RunContext(config={}, choices={}, seed=0)
    family = Family(body)
    nodes = boundary_nodes(body.mesh.triangles, exclude=np.flatnonzero(body.clamped))
    cols = landmark_columns(nodes)

    def embed(n, seed):
        Y = family.snapshots(disc(n, seed), cols)
        model = ctx.make("embedder", "nlie", n_components=2, n_stress_neighbors=200,
                         alpha=0.99)
        t0 = time.perf_counter()
        model.fit_transform(Y)
        info = model.info_
        return (time.perf_counter() - t0, info["newton_iter"],
                info["grad_max"] / info["grad_tol"], bool(info["converged"]))
    ctx.make("embedder", "nlie", n_stress_neighbors=20, seed_landmarks=50).fit_transform(
        family.snapshots(disc(300, 99), cols))                    # numba compile
    return len(nodes), {n: embed(n, SNAPSHOT_SEED + 1) for n in sizes}


def house_nlie_reference():
    """(N, seconds) of the house NLIE benchmark's stored run (swiss roll), if present."""
    path = Path(__file__).parent / "results" / "bench_nlie.nc"
    try:
        import xarray as xr

        with xr.open_dataset(path) as ds:
            return list(zip(ds["n_points"].values.tolist(), ds["seconds"].values.tolist()))
    except (OSError, ValueError, KeyError, ImportError):
        return []


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="small sizes, a smoke check")
    p.add_argument("--large", action="store_true", help="NLIE also at N = 50 000")
    p.add_argument("--full-steps", type=int, default=None, help="steps of the timed full solve")
    p.add_argument("--rom-steps", type=int, default=200_000,
                   help="steps of the timed tabulated reduced run")
    a = p.parse_args(argv)
    if a.quick:
        n_tri, n_snap, n_nodes, grid, sizes = 2000, 4000, 400, 65, [2000]
    else:
        n_tri, n_snap, n_nodes, grid = 9428, 20_000, 2000, 129
        sizes = [5000, 10_000, 20_000] + ([50_000] if a.large else [])
    full_steps = a.full_steps or (2000 if a.quick else 20_000)
    rom_steps = min(a.rom_steps, 20_000) if a.quick else a.rom_steps

    import numba

    print(f"bench_rom: {os.cpu_count()} cores, numba threads {numba.get_num_threads()}"
          f"{' (quick)' if a.quick else ''}", flush=True)
    us_full, wall_full, warm, n_nodes_full = time_full(n_tri, full_steps)
    per_s_full = us_full * 1e-6 / DT_FULL
    print(f"\n1. full model: neo_hookean_2d, n_triangles {n_tri} ({n_nodes_full} nodes), "
          f"lumped mass, Δt = {DT_FULL:g}")
    print(f"   {full_steps} steps in {wall_full:.2f} s (a 10-step solve, setup included: "
          f"{warm:.2f} s)")
    print(f"   {'µs / step':<34}{us_full:>12.1f}")
    print(f"   {'wall s / simulated s':<34}{per_s_full:>12.2f}", flush=True)

    ctx = _context(n_tri, 1)
    body = ctx.plugin("physics").build_body()
    r = time_reduced(body, n_snap, n_nodes, grid, rom_steps)
    per_s_tab = r["table_us"] * 1e-6 / DT_ROM
    per_s_dir = r["direct_us"] * 1e-6 / DT_ROM
    print(f"\n2. reduced model: {n_snap} snapshots (made in {r['snapshots_s']:.1f} s), "
          f"n_bins {r['n_bins']} → {r['n_nodes']} LME nodes, fit {r['fit_s']:.1f} s, "
          f"residual {r['residual']:.2e} ({r['n_unfitted']} unfitted); ω₁…₄ = "
          f"{', '.join(f'{w:.3g}' for w in r['omega'])} rad/s")
    print(f"   table {grid} × {grid}: built in {r['table_s']:.1f} s, table_error "
          f"{r['table_error']:.2e} (M̃ {r['mass_error']:.2e}, Ṽ {r['potential_error']:.2e}), "
          f"{100 * r['usable']:.0f} % of the cells usable")
    print(f"   tabulated run: {r['rom_steps']} steps of Δt = {DT_ROM:g} in "
          f"{r['table_wall']:.3f} s, max |q| {r['rom_radius']:.2f} (Ṽ ≤ E₀ only within "
          f"|q| < {r['confined']:.2f}), energy range / |E(0)| {r['rom_energy_drift']:.1e}")
    print(f"   {'model':<34}{'µs / step':>12}{'wall s / sim s':>16}{'speed-up':>10}")
    for name, us, per_s in (("full (Δt 2e-5)", us_full, per_s_full),
                            ("reduced, tabulated (Δt 1e-4)", r["table_us"], per_s_tab),
                            ("reduced, direct (Δt 1e-4)", r["direct_us"], per_s_dir)):
        print(f"   {name:<34}{us:>12.3g}{per_s:>16.4g}{per_s_full / per_s:>9.3g}×")
    speedup = per_s_full / per_s_tab
    print(f"   tabulated speed-up {speedup:.3g}× (target ≥ {TARGET_SPEEDUP:g}×: "
          f"{'met' if speedup >= TARGET_SPEEDUP else 'NOT met'}); the direct reduced step "
          f"is {'slower' if per_s_dir > per_s_full else 'faster'} than the full model "
          f"({per_s_full / per_s_dir:.2g}×)", flush=True)

    n_land, secs = time_nlie(body, sizes)
    print(f"\n3. NLIE (d 2, k_G 200, α 0.99) on {n_land} boundary landmark nodes "
          f"(D = {2 * n_land})")
    print(f"   {'N':>7}{'seconds':>10}{'Newton':>8}{'grad/tol':>10}{'converged':>11}")
    for n, (s, it, g, conv) in secs.items():
        print(f"   {n:>7}{s:>10.1f}{it:>8}{g:>10.3g}{str(conv):>11}")
    ref = house_nlie_reference()
    if ref:
        print("   reference, benchmarks/bench_nlie.py (swiss roll, D = 3), stored run: "
              + ", ".join(f"N {n}: {s:.1f} s" for n, s in ref))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
