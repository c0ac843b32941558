"""SandCV and biased-MD speed on alanine dipeptide in vacuum (issue 22, Speed).

Measures, on this machine:
- plain OpenMM Langevin steps/s (2 fs) on the Reference and CPU platforms, stepping in
  chunks (``integrator.step(1000)``) and one step per Python call;
- one warm-started SandCV evaluation (ξ and ∂ξ/∂x of the 10 heavy atoms, D = 30; Isomap
  d = 2, LME), µs, from the previous MD step's first-order prediction;
- eABF-biased MD on ξ₁ of that SandCV (:func:`pointatlas_molecular.biased_md.run_eabf`:
  positions out, CV, force parameters in, every step) and on φ, steps/s and ns/day, and the
  ratio to plain MD on the same platform.

Run: ``MPLBACKEND=Agg python benchmarks/bench_sandcv.py`` (about 30 s).

Measured here (2-core machine, quiet, 2026-12-06, after the eABF step became a numba kernel
and the loop lost its numpy/unit overheads; the run takes ~30 s):
  plain MD: Reference 84 177 steps/s (14 546 ns/day), CPU 2 891 steps/s (500 ns/day)
  SandCV evaluation: median 37.3 µs (90th percentile 44.6 µs); Newton steps of 200
    configurations: 2 (168), 3 (30), 4 (1), 18 (1)
  eABF on SandCV ξ₁: Reference 7 940 steps/s (1 372 ns/day, 9 % of plain MD);
    CPU 1 736 steps/s (300 ns/day, 60 % of plain MD)
  eABF on φ: Reference 8 652 steps/s (10 %); CPU 1 802 steps/s (62 %)
  exploration, 200 ps of eABF on ξ₁: no sample with 0 < φ < 120° (nor in training)
The ≥ 50 % of plain MD target is met on the CPU platform and missed on Reference, whose step
(~12 µs for 22 atoms) is shorter than one Python round trip: per step, positions out (3 µs),
SandCV (~40 µs), the eABF step (~7 µs), 10 force-parameter updates (~25 µs), loop (~15 µs).
Reference stays the faster platform for biased alanine dipeptide (4.6× CPU's biased rate).
Before (2026-12-05, loaded machine): Reference 1 840–2 730 steps/s (3–5 %), CPU 97–624 (2–18 %).
"""
from __future__ import annotations

import time

import numpy as np

from pointatlas_approximants.lme import LocalMaxEnt
from pointatlas_embedders.isomap import Isomap
from pointatlas_molecular.biased_md import run_eabf
from pointatlas_molecular.dihedral_cv import DihedralCV
from pointatlas_molecular.eabf import EABF
from pointatlas_molecular.engine import (PHI, dihedrals, langevin_context, load_system,
                                         positions_of, unbiased_frames)
from pointatlas_molecular.training import train_sandcv

KT = 0.0083144626 * 300
NS_DAY = 0.002e-3 * 86400


def plain_rate(mol, platform, n, chunk):
    ctx, integ = langevin_context(mol.system, mol.positions, 1, platform)
    integ.step(200)
    t = time.perf_counter()
    for _ in range(n // chunk):
        integ.step(chunk)
    return n / (time.perf_counter() - t)


def main():
    mol = load_system()
    heavy = mol.heavy_atoms
    plain = {}
    for platform in ("Reference", "CPU"):
        big = 20000 if platform == "Reference" else 4000
        plain[platform] = plain_rate(mol, platform, big, 1000)
        one = plain_rate(mol, platform, big // 4, 1)
        print(f"plain {platform}: {plain[platform]:.0f} steps/s in chunks "
              f"({plain[platform] * NS_DAY:.1f} ns/day), {one:.0f} steps/s one per call")
    frames = unbiased_frames(mol, 2000, 50, 11)
    cv, Z, Q = train_sandcv(frames, heavy, Isomap(n_components=2, n_neighbors=12),
                            LocalMaxEnt(gamma=0.8, tol=1e-14), 12, 1e-10)
    ctx, integ = langevin_context(mol.system, frames[-1], 5)
    times, steps = [], []
    for _ in range(200):
        integ.step(99)
        b = positions_of(ctx)[heavy]
        integ.step(1)
        x = positions_of(ctx)[heavy]
        p = cv(b)
        if not p.ok:
            continue
        start = cv.predict(p, b, x)
        t = time.perf_counter()
        for _ in range(20):
            v = cv(x, start)
        times.append((time.perf_counter() - t) / 20)
        if v.ok:
            steps.append(v.steps)
    print(f"SandCV evaluation (warm-started, Python call included): median "
          f"{1e6 * np.median(times):.1f} µs, 90th percentile {1e6 * np.percentile(times, 90):.1f}"
          f" µs; Newton steps of the accepted ones (count by steps 0, 1, …): "
          f"{np.bincount(steps).tolist()}, {len(times)} of 200 configurations accepted")
    lo, hi = np.percentile(Q[:, 0], [1, 99])
    for platform in ("Reference", "CPU"):
        n = 20000 if platform == "Reference" else 5000
        for name, c, atoms, e in (
                ("SandCV ξ₁", cv, heavy, EABF(lo, hi, 40, k=5000.0, mass=5.0, kT=KT,
                                              lam=float(Q[-1, 0]))),
                ("φ", DihedralCV(PHI), np.array(PHI),
                 EABF(-np.pi, np.pi, 72, k=1000.0, mass=0.5, kT=KT, period=2 * np.pi))):
            run = run_eabf(mol, c, atoms, e, n, 3, platform=platform, positions=frames[-1])
            r = run.steps_per_second
            print(f"eABF on {name}, {platform}: {r:.0f} steps/s ({r * NS_DAY:.1f} ns/day), "
                  f"{100 * r / plain[platform]:.0f} % of plain MD; refused steps "
                  f"{run.n_refused}")
    # exploration: 200 ps of eABF on ξ₁ (Reference): does it reach φ > 0 (C7ax / αL), which
    # the training run did not sample?
    train_phi = dihedrals(frames)[:, 0]
    e = EABF(lo, hi, 40, k=5000.0, mass=5.0, kT=KT, lam=float(Q[-1, 0]))
    n = 100_000
    run = run_eabf(mol, cv, heavy, e, n, 4, positions=frames[-1], save_atoms=np.arange(22))
    phi = dihedrals(run.frames)[:, 0]
    basin = (phi > 0) & (phi < 120)
    first = np.flatnonzero(basin)
    trained = np.mean((train_phi > 0) & (train_phi < 120))
    print(f"training run: fraction with 0 < φ < 120°: {trained:.4f}; "
          f"eABF on ξ₁ for {n * 0.002:.0f} ps: fraction {basin.mean():.4f}, first visit "
          f"{first[0] * 10 * 0.002 if len(first) else float('nan'):.1f} ps, refused steps "
          f"{run.n_refused} (first at step {run.first_refused_step}), ξ₁ visited "
          f"[{np.nanmin(run.xi):.3f}, {np.nanmax(run.xi):.3f}] of the training range "
          f"[{Q[:, 0].min():.3f}, {Q[:, 0].max():.3f}]")


if __name__ == "__main__":
    main()
