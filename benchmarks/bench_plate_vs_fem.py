"""Benchmark: pointatlas against a finite-element peer on the clamped square plate (issue 17).

The pointatlas ``shell_plate`` experiment (experiments/shell_plate.yaml: L = 10, h = 0.1,
E = 1e6, ν = 0.3, F = 200 at the centre; quarter model, clamped edges x, y = L/2, symmetry
edges x, y = 0; thesis L1337, BENCHMARKS.md) is solved side by side with scikit-fem's
conforming Argyris element (ElementTriArgyris, quintic C¹ triangles) on the same quarter:

* Argyris: the Kirchhoff plate bilinear form a(w, v) = ∫ D[(1−ν) ∇²w : ∇²v + ν Δw Δv]
  (D = E h³ / 12(1 − ν²); the plate bending energy of Timoshenko & Woinowsky-Krieger,
  *Theory of plates and shells*, 1959) written here; the quarter of F at the centre
  through ``basis.probes``.
  Boundary DOFs (the Argyris DOFs are w, w_x, w_y, w_xx, w_xy, w_yy at vertices and the
  normal derivative w_n at edge midpoints): a symmetry edge x = 0 holds w_x ≡ 0, i.e. w_x,
  w_xy, w_n; a clamped edge x = L/2 holds w ≡ w_x ≡ 0, i.e. w, w_x, w_y, w_xy, w_yy, w_n
  (the same with x ↔ y). Meshes: uniform n×n squares cut in two (``regular``), and the
  Delaunay triangulation of the jittered point cloud (``jittered``; meshing is timed).
* pointatlas: the experiment's physics settings read from experiments/shell_plate.yaml,
  with the default LME charts and, on the jittered clouds, also the cubic moving
  least-squares basis with exact Hessians (``approximant=mls approximant.degree=3``),
  the square_plate source at a sequence of ``n_points``, ``sampling = structured`` and
  ``random`` (the grid jittered by up to 0.3 spacing, edge points slide along their edge),
  the source RNG seeded as the CLI seeds it; one jittered run is repeated through the CLI
  (``pointatlas experiment=shell_plate ...``) and must give the same displacement.

The converged Kirchhoff value is this script's Richardson extrapolation of three regular
Argyris meshes (n = 8, 16, 32; observed order from the three); relative errors are
against it.
For each series it interpolates, in log–log between consecutive runs, the DOF and wall time
(point cloud or mesh to displacement) at which the relative error reaches 1e-3 and 2e-4.
Issue target: pointatlas within 2× the Argyris DOF and 5× its time at equal accuracy.

Roundoff: skfem's ElementGlobal builds each element's basis by inverting a Vandermonde
matrix of *global* monomials up to degree 5, whose roundoff grows like (L/h)^5 ε.
Measured while writing this script: equivalent meshings of the same n = 64 mesh
(translated to [−L/4, L/4]², vertices reordered) give deflections up to 3.5e-7 apart
(relative), at n = 128 (1.5e5 DOF) 2e-6, at n = 32 5e-9. So the extrapolation uses the
three finest meshes with n ≤ 32 (``RICHARDSON_MAX_N``); n = 64 is run as a check of it
(its error should be a quarter of n = 32's). The converged value is uncertain by well
under 1e-6 relative, 200 times below the smaller target.

Usage: .venv/bin/python benchmarks/bench_plate_vs_fem.py [out.nc] [--quick]
(needs the ``bench`` extra: pip install -e '.[bench]', i.e. scikit-fem)
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
import zlib
from itertools import zip_longest
from pathlib import Path

import numpy as np
import xarray as xr

import pointatlas
from pointatlas_atlas.settings import AtlasSettings
from pointatlas_physics.kirchhoff_love.analysis import build_model, displacement_at, solve_linear
from pointatlas_studies.shell import SHELL_MARKERS_PER_PATCH

ROOT = Path(__file__).resolve().parent.parent
EXPERIMENT = ROOT / "experiments" / "shell_plate.yaml"
ISSUE_CONVERGED = 1.225665      # issue 17: refined Argyris meshes (0.0056120 F L²/D)
BENCHMARKS_CONVERGED = 0.0056122  # BENCHMARKS.md / thesis L1337, in F L²/D
TARGETS = (1e-3, 2e-4)
SEED = 0                        # the CLI's default run seed
RICHARDSON_MAX_N = 32           # finest Argyris mesh in the extrapolation (roundoff)
MLS = "pointatlas-mls3"         # pointatlas with approximant=mls approximant.degree=3
COMPARISONS = ("pointatlas/Argyris, regular", "pointatlas/Argyris, jittered",
               f"{MLS}/Argyris, jittered")


def experiment():
    """The shell_plate experiment's physics plugin (its settings) and plate data."""
    from omegaconf import OmegaConf

    exp = OmegaConf.to_container(OmegaConf.load(EXPERIMENT))
    physics = pointatlas.load_plugin("physics", "kirchhoff_love")(**exp["physics"])
    settings = physics.shell_settings()
    (load,) = settings.loads
    E, nu, h = settings.young_modulus, settings.poisson_ratio, settings.thickness
    plate = dict(L=float(exp["source"]["length"]), E=E, nu=nu, h=h,
                 D=E * h ** 3 / (12 * (1 - nu ** 2)),
                 F_quarter=float(-load.force[2]), F=4.0 * float(-load.force[2]))
    if exp["source"]["model"] != "quarter" or list(load.at) != [0.0, 0.0, 0.0]:
        raise SystemExit(f"{EXPERIMENT} no longer is the quarter model loaded at the centre: "
                         "update this benchmark.")
    return settings, plate


# --------------------------------------------------------------------------- point clouds
def source_rng():
    """The generator the CLI gives the source (RunContext.rng('source') with seed 0)."""
    return np.random.default_rng(np.random.SeedSequence([SEED, zlib.crc32(b"source")]))


def plate_cloud(n_points: int, sampling: str, L: float):
    return pointatlas.load_plugin("sources", "square_plate")(
        model="quarter", length=L, n_points=n_points, sampling=sampling).load(source_rng())


# --------------------------------------------------------------------------- Argyris
def argyris_deflection(mesh_points, triangles, plate):
    """Centre deflection of the Argyris quarter plate on the given triangulation of
    [0, L/2]² (centre at the origin). Returns (deflection, total DOF, free DOF)."""
    from skfem import Basis, BilinearForm, ElementTriArgyris, MeshTri, condense, solve
    from skfem.helpers import dd, ddot, trace

    D, nu, half = plate["D"], plate["nu"], plate["L"] / 2
    mesh = MeshTri(np.ascontiguousarray(mesh_points.T),
                   np.ascontiguousarray(triangles.T))

    @BilinearForm
    def bending(u, v, w):
        return D * ((1 - nu) * ddot(dd(u), dd(v)) + nu * trace(dd(u)) * trace(dd(v)))

    basis = Basis(mesh, ElementTriArgyris())
    K = bending.assemble(basis)

    def on(axis, value):
        return basis.get_dofs(lambda x: np.isclose(x[axis], value, atol=1e-9))

    fixed = np.unique(np.concatenate([
        on(0, 0.0).all(["u_x", "u_xy", "u_n"]),                       # symmetry x = 0
        on(1, 0.0).all(["u_y", "u_xy", "u_n"]),                       # symmetry y = 0
        on(0, half).all(["u", "u_x", "u_y", "u_xy", "u_yy", "u_n"]),  # clamped x = L/2
        on(1, half).all(["u", "u_x", "u_y", "u_xy", "u_xx", "u_n"]),  # clamped y = L/2
    ]))
    centre = basis.probes(np.array([[0.0], [0.0]]))                # the plate's centre
    f = plate["F_quarter"] * centre.toarray()[0]
    w = solve(*condense(K, f, D=fixed))
    return float((centre @ w)[0]), int(basis.N), int(basis.N - fixed.size)


def regular_mesh(n: int, half: float):
    from skfem import MeshTri

    m = MeshTri.init_tensor(np.linspace(0, half, n + 1), np.linspace(0, half, n + 1))
    return m.p.T, m.t.T


def delaunay_mesh(points2d):
    from scipy.spatial import Delaunay

    tri = Delaunay(points2d)
    if len(tri.coplanar) or np.unique(tri.simplices).size != len(points2d):
        raise RuntimeError("Delaunay left points out of the triangulation")
    return points2d, tri.simplices


def timed(fn):
    """(result, wall time, CPU time of the process, repeats): the smallest of 3 calls if
    one takes under 2 s, of 2 under 5 s, else one call (the same rule for both codes)."""
    wall, cpu, repeats = np.inf, np.inf, 0
    while True:
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        wall = min(wall, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
        repeats += 1
        if repeats >= (3 if wall < 2 else 2 if wall < 5 else 1):
            return out, wall, cpu, repeats


# --------------------------------------------------------------------------- pointatlas
def pointatlas_deflection(cloud, settings, approximant: str = "lme", **options):
    """Centre deflection (along −z) of the shell_plate experiment on ``cloud``: build the
    atlas and the model, solve, read the displacement (as ShellStudy does). ``approximant``
    and ``options``: the chart basis (``approximant=mls approximant.degree=3`` on the
    command line is ``"mls", degree=3``)."""
    a = AtlasSettings(markers_per_patch=SHELL_MARKERS_PER_PATCH)

    def make(family, name, **kw):
        return lambda: pointatlas.load_plugin(family, name)(**kw)

    model = build_model(cloud, settings, a, make("embedders", "pca", n_components=2),
                        make("approximants", approximant, gamma=a.gamma_lme, tol=a.tol_lme,
                             outside="flag", **options),
                        make("approximants", "shepard", gamma=a.gamma_pu, tol=a.tol_pu,
                             outside="flag"))
    solve_linear(model, settings)
    u, _ = displacement_at(model, [0.0, 0.0, 0.0])
    return float(-u[2]), int(model.dof), int(model.dof)


def cli_deflection(n_points: int, sampling: str):
    """The same run through the command line: (displacement, dof) from its results.nc."""
    exe = Path(sys.executable).with_name("pointatlas")
    with tempfile.TemporaryDirectory(prefix="bench_plate_") as tmp:
        subprocess.run([str(exe), "experiment=shell_plate", f"source.n_points={n_points}",
                        f"source.sampling={sampling}", f"seed={SEED}", "study.write_vtp=false",
                        f"outputs_root={tmp}", f"hydra.run.dir={tmp}/run"],
                       check=True, capture_output=True, cwd=tmp)
        with xr.open_dataset(Path(tmp) / "run" / "results.nc") as ds:
            return float(ds["displacement"]), int(ds["dof"])


# --------------------------------------------------------------------------- analysis
def richardson(h, w):
    """Extrapolated value and observed order from the three finest (h, w) (h halving)."""
    (h1, w1), (h2, w2), (h3, w3) = sorted(zip(h, w), reverse=True)[-3:]
    p = np.log(abs(w2 - w1) / abs(w3 - w2)) / np.log(h2 / h3)
    return w3 + (w3 - w2) / ((h2 / h3) ** p - 1), float(p)


def reach(dof, seconds, error, target):
    """DOF and time at which |error| falls to ``target`` and stays below, interpolated in
    log–log between the bracketing runs; (nan, nan, note) if not reached in the runs."""
    order = np.argsort(dof)
    d, t, e = (np.asarray(x, float)[order] for x in (dof, seconds, np.abs(error)))
    above = np.nonzero(e > target)[0]
    if above.size == 0:
        return d[0], t[0], "reached at the smallest run (upper bound)"
    i = above[-1]
    if i == len(e) - 1:
        return np.nan, np.nan, "not reached in the runs"
    s = np.log(e[i] / target) / np.log(e[i] / e[i + 1])
    return (float(np.exp(np.log(d[i]) + s * np.log(d[i + 1] / d[i]))),
            float(np.exp(np.log(t[i]) + s * np.log(t[i + 1] / t[i]))), "interpolated")


def main(out: Path, quick: bool) -> None:
    settings, plate = experiment()
    half, FL2D = plate["L"] / 2, plate["F"] * plate["L"] ** 2 / plate["D"]
    load0 = os.getloadavg()
    grid_n = (2, 4, 8, 16, 32) if quick else (2, 4, 8, 16, 32, 64)
    fem_jitter_n = (25, 49, 121, 289) if quick else (25, 49, 121, 289, 676, 1681)
    pa_n = (49, 121, 256) if quick else (49, 81, 121, 256, 441, 676, 1089)
    pa_jitter_n = (121, 256) if quick else (121, 256, 441, 676, 1089, 1600)
    rows = []  # method, cloud, size, nodes, dof, free dof, deflection, wall, cpu, repeats

    # warm-ups (imports, numba caches, skfem's lambdas): not timed
    argyris_deflection(*regular_mesh(2, half), plate)
    pointatlas_deflection(plate_cloud(49, "structured", plate["L"]), settings)

    # jobs (method, kind, size, nodes, solve); the two codes' runs alternate, small to
    # large, so that a change of the machine's load hits both alike
    fem_jobs, pa_jobs = [], []
    for n in grid_n:
        fem_jobs.append(("argyris", "regular", n, (n + 1) ** 2,
                         lambda n=n: argyris_deflection(*regular_mesh(n, half), plate)))
    for n in fem_jitter_n:
        xy = plate_cloud(n, "random", plate["L"]).points[:, :2]
        fem_jobs.append(("argyris", "jittered", n, len(xy),
                         lambda xy=xy: argyris_deflection(*delaunay_mesh(xy), plate)))
    for sampling, sizes, kind in (("structured", pa_n, "regular"),
                                  ("random", pa_jitter_n, "jittered")):
        for n in sizes:
            cloud = plate_cloud(n, sampling, plate["L"])
            pa_jobs.append(("pointatlas", kind, n, len(cloud.points),
                            lambda cloud=cloud: pointatlas_deflection(cloud, settings)))
            if kind == "jittered":  # the same clouds on the cubic moving least-squares basis
                pa_jobs.append((MLS, kind, n, len(cloud.points),
                                lambda cloud=cloud: pointatlas_deflection(
                                    cloud, settings, "mls", degree=3)))
    for job in (j for pair in zip_longest(fem_jobs, pa_jobs) for j in pair if j):
        method_, kind, size_, nodes_, solve_ = job
        (w_, dof_, free_), wall, cpu_, reps_ = timed(solve_)
        rows.append((method_, kind, size_, nodes_, dof_, free_, w_, wall, cpu_, reps_))
        print(f"{method_:15s} {kind:8s} {nodes_:5d} nodes: {dof_:6d} DOF  w = {w_:.9f}  "
              f"{wall:7.3f} s wall, {cpu_:7.3f} s CPU", flush=True)
    rows.sort(key=lambda r: (r[0], r[1] != "regular", r[2]))

    # the API runs are the experiment: one jittered run again through the CLI
    w_cli, dof_cli = cli_deflection(pa_jitter_n[0], "random")
    api = next(r for r in rows if r[:3] == ("pointatlas", "jittered", pa_jitter_n[0]))
    cli_difference = abs(w_cli - api[6]) / abs(api[6])
    if cli_difference > 1e-8 or dof_cli != api[4]:
        raise SystemExit(f"the CLI run differs from the API run ({w_cli} vs {api[6]}, "
                         f"{dof_cli} vs {api[4]} DOF): this benchmark no longer measures "
                         "the shell_plate experiment.")

    fem = [r for r in rows if r[:2] == ("argyris", "regular") and r[2] <= RICHARDSON_MAX_N]
    converged, order = richardson([half / r[2] for r in fem], [r[6] for r in fem])
    finest = max((r for r in rows if r[:2] == ("argyris", "regular")), key=lambda r: r[2])
    method, cloud_kind, size, nodes, dof, free, w, secs, cpu, reps = map(np.array, zip(*rows))
    err = (w - converged) / converged
    series = [("argyris", "regular"), ("argyris", "jittered"), ("pointatlas", "regular"),
              ("pointatlas", "jittered"), (MLS, "jittered")]
    need_dof = np.full((len(series), len(TARGETS)), np.nan)
    need_time, need_cpu = np.full_like(need_dof, np.nan), np.full_like(need_dof, np.nan)
    notes = []
    for i, (m, c) in enumerate(series):
        sel = (method == m) & (cloud_kind == c)
        for j, tgt in enumerate(TARGETS):
            need_dof[i, j], need_time[i, j], note = reach(dof[sel], secs[sel], err[sel], tgt)
            need_cpu[i, j] = reach(dof[sel], cpu[sel], err[sel], tgt)[1]
            notes.append(f"{m} {c} at {tgt:g}: {note}")
    # pointatlas / Argyris (regular mesh; jittered cloud vs Argyris on its Delaunay mesh)
    ours, peer = [2, 3, 4], [0, 1, 1]
    dof_ratio = need_dof[ours] / need_dof[peer]
    time_ratio = need_time[ours] / need_time[peer]
    cpu_ratio = need_cpu[ours] / need_cpu[peer]
    load1 = os.getloadavg()

    print(f"\nconverged centre deflection (Richardson, Argyris n = {fem[-3][2]}, {fem[-2][2]}, "
          f"{fem[-1][2]}; observed order {order:.3f} in h): w = {converged:.8f} "
          f"= {converged / FL2D:.8f} F L²/D")
    print(f"  vs issue 17's 1.225665: {(ISSUE_CONVERGED - converged) / converged:+.2e}; "
          f"vs BENCHMARKS 0.0056122 F L²/D = {BENCHMARKS_CONVERGED * FL2D:.7f}: "
          f"{(BENCHMARKS_CONVERGED * FL2D - converged) / converged:+.2e} (relative)")
    if finest[2] > fem[-1][2]:
        print(f"  check: Argyris n = {finest[2]} has error "
              f"{(finest[6] - converged) / converged:+.3e}, the extrapolation predicts "
              f"{(fem[-1][6] - converged) / converged / (finest[2] / fem[-1][2]) ** order:+.3e}")
    print(f"errors below are against w = {converged:.8f} (this run's extrapolation)\n")
    print(f"{'method':15s} {'cloud':8s} {'nodes':>6s} {'DOF':>7s} {'w':>12s} {'rel.err':>9s} "
          f"{'wall/s':>8s} {'CPU/s':>8s} reps")
    for k in range(len(rows)):
        print(f"{method[k]:15s} {cloud_kind[k]:8s} {nodes[k]:6d} {dof[k]:7d} {w[k]:12.8f} "
              f"{err[k]:+9.2e} {secs[k]:8.3f} {cpu[k]:8.3f} {reps[k]}")
    print(f"\n{'to reach':26s} " + "  ".join(
        f"{'DOF @' + format(t, 'g'):>11s} {'wall @' + format(t, 'g'):>12s} "
        f"{'CPU @' + format(t, 'g'):>11s}" for t in TARGETS))
    for i, (m, c) in enumerate(series):
        print(f"{m + ' ' + c:26s} " + "  ".join(
            f"{need_dof[i, j]:11.0f} {need_time[i, j]:10.3f} s {need_cpu[i, j]:9.3f} s"
            for j in range(len(TARGETS))))
    for i, c in enumerate(COMPARISONS):
        print(f"{c}: " + "; ".join(
            f"@{t:g}: DOF × {dof_ratio[i, j]:.2f}, wall × {time_ratio[i, j]:.1f}, "
            f"CPU × {cpu_ratio[i, j]:.1f}" for j, t in enumerate(TARGETS)))
    print("(issue 17 target: ≤ 2× DOF and ≤ 5× time at equal accuracy; nan: a series does not "
          "reach the error in its runs)")
    print("notes: " + "; ".join(n for n in notes if "interpolated" not in n))
    print(f"load average at start {load0[0]:.2f}, at end {load1[0]:.2f} on {os.cpu_count()} "
          f"cores; CLI check: relative difference {cli_difference:.1e}")

    run_dim, s_dim = "run", "series"
    ds = xr.Dataset(
        {"nodes": (run_dim, nodes, {"long_name": "mesh vertices or cloud points",
                                    "units": "1"}),
         "dof": (run_dim, dof, {"long_name": "degrees of freedom (Argyris: all DOF of the "
                                "basis; pointatlas: 3 × (points + ghosts))", "units": "1"}),
         "free_dof": (run_dim, free, {"long_name": "DOF left after the boundary conditions "
                                      "(pointatlas: all, supports by augmented Lagrangian)",
                                      "units": "1"}),
         "deflection": (run_dim, w, {"long_name": "centre deflection along −z",
                                     "units": "length"}),
         "relative_error": (run_dim, err, {"long_name": "(deflection − converged) / converged",
                                           "units": "1"}),
         "wall_time": (run_dim, secs, {"long_name": "point cloud (or mesh) to displacement, "
                                       "best of the repeats", "units": "s"}),
         "cpu_time": (run_dim, cpu, {"long_name": "CPU time of the process (all threads), "
                                     "point cloud (or mesh) to displacement", "units": "s"}),
         "repeats": (run_dim, reps, {"long_name": "timed repeats", "units": "1"}),
         "dof_needed": ((s_dim, "target"), need_dof, {
             "long_name": "DOF to reach the relative error (log–log interpolation)",
             "units": "1"}),
         "time_needed": ((s_dim, "target"), need_time, {
             "long_name": "wall time to reach the relative error (log–log interpolation)",
             "units": "s"}),
         "cpu_needed": ((s_dim, "target"), need_cpu, {
             "long_name": "CPU time to reach the relative error (log–log interpolation)",
             "units": "s"}),
         "cpu_ratio": (("comparison", "target"), cpu_ratio, {
             "long_name": "pointatlas CPU time / Argyris CPU time at equal accuracy",
             "units": "1"}),
         "dof_ratio": (("comparison", "target"), dof_ratio, {
             "long_name": "pointatlas DOF / Argyris DOF at equal accuracy (target ≤ 2)",
             "units": "1"}),
         "time_ratio": (("comparison", "target"), time_ratio, {
             "long_name": "pointatlas time / Argyris time at equal accuracy (target ≤ 5)",
             "units": "1"}),
         "converged_deflection": ((), converged, {
             "long_name": "Richardson extrapolation of the regular Argyris meshes n = "
                          + ", ".join(str(r[2]) for r in fem[-3:]), "units": "length"}),
         "converged_coefficient": ((), converged / FL2D, {
             "long_name": "converged deflection / (F L²/D)", "units": "1"}),
         "observed_order": ((), order, {"long_name": "observed convergence order in h of the "
                                        "Argyris centre deflection", "units": "1"}),
         "cli_difference": ((), cli_difference, {
             "long_name": "relative difference of a CLI run to the same API run",
             "units": "1"})},
        coords={"run": (run_dim, np.arange(len(rows)), {"long_name": "run", "units": "1"}),
                "method": (run_dim, method.astype(str), {"long_name": "method", "units": "1"}),
                "comparison": ("comparison", list(COMPARISONS), {
                    "long_name": "pointatlas series / Argyris series on the same point set",
                    "units": "1"}),
                "cloud_kind": (run_dim, cloud_kind.astype(str), {
                    "long_name": "regular grid or jittered cloud", "units": "1"}),
                "size": (run_dim, size, {"long_name": "mesh divisions n (regular Argyris) or "
                                         "source.n_points", "units": "1"}),
                "series": (s_dim, [f"{m} {c}" for m, c in series], {"long_name": "series",
                                                                   "units": "1"}),
                "target": ("target", list(TARGETS), {"long_name": "relative error",
                                                     "units": "1"})},
        attrs={"title": "clamped square plate, central point load: pointatlas vs scikit-fem "
                        "Argyris (quarter model)",
               "references": f"issue 17: {ISSUE_CONVERGED}; BENCHMARKS.md: "
                             f"{BENCHMARKS_CONVERGED} F L²/D = {BENCHMARKS_CONVERGED * FL2D}",
               "notes": "; ".join(notes),
               "load_average": f"{load0[0]:.2f} at start, {load1[0]:.2f} at end, "
                               f"{os.cpu_count()} cores (shared machine)",
               "skfem_version": __import__("skfem").__version__})
    out.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--quick"]
    here = Path(__file__).parent
    main(Path(args[0]) if args else here / "results/plate_vs_fem.nc", "--quick" in sys.argv)
