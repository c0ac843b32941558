"""SandCV's own checks on alanine dipeptide (issue 22's ``sandcv_gradient``).

Training: ``trajectory`` (a DCD/XTC/HDF5/… file of the system, read by mdtraj, every frame
used) or else an unbiased Langevin run (300 K, 2 fs, H-bonds constrained; ``n_frames`` frames
every ``stride`` steps after ``equilibration``), its heavy atoms (D = 30) superposed by mdtraj,
embedded by the ``embedder`` (Isomap, d = 2), parametrised by the ``approximant`` (LME) on
``n_bins`` binned nodes (:mod:`pointatlas_molecular.sandcv`). Tests: ``n_test``
configurations of an independent run (another seed), off the training set. For each:

- ``gradient_error``: max_ij |∂ξ/∂x − FD|_ij / max_ij |FD|_ij, FD the fourth-order central
  difference (h = ``fd_step`` nm) of ξ (every evaluation warm-started from ξ(x) and converged
  to 1e-12 relative, so that the reference is not limited by the MD tolerance);
- ``rigid_motion_error``: max |ξ(Q x + t) − ξ(x)| over a random rotation Q and translation t,
  relative to the extent of the embedding (both from the same start);
- ``newton_steps``: Newton steps of the projection warm-started as during biased MD: from
  the first-order prediction ξ(x') + ∂ξ/∂x(x') (x − x') of the configuration x' one MD step
  (2 fs) earlier (:meth:`SandCV.predict`); the step below the tolerance counts.

Configurations whose projection is flagged (outside the parametrised region, near the focal
set; :mod:`pointatlas_molecular.projection`) are counted, not checked: the CV refuses them.
``evaluation_time``: µs per warm-started ξ and ∂ξ/∂x (Python call included).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.constraints import Interval
from pointatlas.stores_config import stores_config
from pointatlas_studies.reduced_pendulum import _v


@dataclass
class SandCVGradientSettings:
    system: str = "alanine_dipeptide_vacuum"
    platform: str = "Reference"
    trajectory: Optional[str] = None
    n_frames: int = 2000
    stride: int = 50
    equilibration: int = 5000
    n_bins: int = 12
    n_test: int = 100
    test_stride: int = 500
    fd_step: float = 1e-5
    newton_tol: float = 1e-10
    min_conditioning: float = 0.1
    parameter_constraints: ClassVar[dict] = {
        "n_frames": [Interval(int, 20, None)], "stride": [Interval(int, 1, None)],
        "equilibration": [Interval(int, 0, None)], "n_bins": [Interval(int, 4, None)],
        "n_test": [Interval(int, 1, None)], "test_stride": [Interval(int, 1, None)],
        "fd_step": [Interval(float, 0, 0.01, closed="right")],
        "newton_tol": [Interval(float, 0, 1e-4, closed="right")],
        "min_conditioning": [Interval(float, 0, 1)]}


def fd_gradient(cv, x, xi, h):
    """Fourth-order central differences of ξ at x (n, 3): (d, n, 3)."""
    out = np.empty((cv.dim,) + x.shape)
    for i in range(x.shape[0]):
        for a in range(3):
            vals = []
            for s in (-2, -1, 1, 2):
                e = x.copy()
                e[i, a] += s * h
                vals.append(cv(e, xi, tol=1e-12).xi)
            out[:, i, a] = (vals[0] - 8 * vals[1] + 8 * vals[2] - vals[3]) / (12 * h)
    return out


@stores_config
class SandCVGradient:
    """SandCV on alanine dipeptide: gradient against finite differences, rigid motions,
    Newton steps."""

    Config = SandCVGradientSettings
    description: ClassVar[str] = ("SandCV's checks: ∂ξ/∂x against finite differences, "
                                  "invariance to rigid motions, warm-started Newton steps.")

    def run(self, ctx):
        import xarray as xr
        from scipy.spatial.transform import Rotation

        from pointatlas_molecular.engine import (dihedrals, langevin_context, load_system,
                                                 positions_of, unbiased_frames)
        from pointatlas_molecular.training import train_sandcv

        mol = load_system(self.system)
        heavy = mol.heavy_atoms
        seeds = ctx.rng("md").integers(1, 2**31 - 1, 2)
        with ctx.timed("training_md"):
            t0 = time.perf_counter()
            if self.trajectory:
                from pointatlas_molecular.ensemble import read_trajectory

                frames = read_trajectory(self.trajectory, mol.topology, len(mol.positions))
                n_steps = 0
            else:
                frames = unbiased_frames(mol, self.n_frames, self.stride, int(seeds[0]),
                                         self.equilibration, self.platform)
                n_steps = self.equilibration + self.n_frames * self.stride
            md_wall = time.perf_counter() - t0
        with ctx.timed("training"):
            cv, Z, Q = train_sandcv(frames, heavy, ctx.plugin("embedder"),
                                    ctx.plugin("approximant"), self.n_bins, self.newton_tol,
                                    self.min_conditioning)
        extent = float(np.max(np.ptp(Q, axis=0)))
        ctx_md, integ = langevin_context(mol.system, frames[-1], int(seeds[1]), self.platform)
        integ.step(self.equilibration)
        rng = ctx.rng("rigid")
        n = self.n_test
        grad_err, rigid_err = np.full(n, np.nan), np.full(n, np.nan)
        steps, status = np.zeros(n, int), np.zeros(n, int)
        dist, cond = np.full(n, np.nan), np.full(n, np.nan)
        phipsi = np.empty((n, 2))
        times = []
        with ctx.timed("checks"):
            for k in ctx.progress(range(n), desc="test configurations"):
                integ.step(self.test_stride - 1)
                before = positions_of(ctx_md)[heavy]
                integ.step(1)
                full = positions_of(ctx_md)
                x = full[heavy]
                phipsi[k] = dihedrals(full[None])[0]
                prev = cv(before)
                start = cv.predict(prev, before, x) if prev.ok else None
                v = cv(x, start)
                status[k], dist[k], cond[k] = v.status, v.distance, v.conditioning
                if not (prev.ok and v.ok):
                    status[k] = v.status if not v.ok else prev.status
                    continue
                steps[k] = v.steps
                t = time.perf_counter()
                for _ in range(20):
                    cv(x, start)
                times.append((time.perf_counter() - t) / 20)
                fd = fd_gradient(cv, x, v.xi, self.fd_step)
                grad_err[k] = np.max(np.abs(v.gradient - fd)) / np.max(np.abs(fd))
                R = Rotation.random(random_state=int(rng.integers(2**31)))
                moved = R.apply(x) + rng.normal(0.0, 2.0, 3)
                rigid_err[k] = np.max(np.abs(cv(moved, start).xi - v.xi)) / extent
        ok = status == 0
        ds = xr.Dataset(coords={"configuration": ("configuration", np.arange(n),
                                                  {"long_name": "test configuration",
                                                   "units": "1"})})
        per = (("gradient_error_per_configuration", grad_err, "max |∂ξ/∂x − FD| / max |FD|",
                "1"), ("rigid_motion_error_per_configuration", rigid_err,
                       "max |ξ(Qx + t) − ξ(x)| / extent of ξ", "1"),
               ("newton_steps", steps, "Newton steps warm-started one MD step back", "1"),
               ("status", status, "projection status (0 ok, 1 outside, 2 not converged, 3 "
                "not a minimum, 4 near the focal set, 5 folded)", "1"),
               ("distance", dist, "distance to the manifold |X(ξ) − z|", "nm"),
               ("conditioning", cond, "conditioning c of the projection (1 on the manifold)",
                "1"),
               ("phi", phipsi[:, 0], "backbone dihedral φ", "degree"),
               ("psi", phipsi[:, 1], "backbone dihedral ψ", "degree"))
        for name, val, long, units in per:
            _v(ds, name, val, long, units, ("configuration",))
        ns_day = n_steps * 0.002e-3 / md_wall * 86400 if n_steps else np.nan
        for name, val, long, units in (
                ("gradient_error", np.nanmax(grad_err) if ok.any() else np.nan,
                 "worst max |∂ξ/∂x − FD| / max |FD| over the accepted configurations", "1"),
                ("rigid_motion_error", np.nanmax(rigid_err) if ok.any() else np.nan,
                 "worst |ξ(Qx + t) − ξ(x)| / extent of ξ", "1"),
                ("max_newton_steps", int(steps[ok].max()) if ok.any() else -1,
                 "most Newton steps of a warm-started projection", "1"),
                ("n_accepted", int(ok.sum()), "test configurations the CV accepted", "1"),
                ("n_flagged", int((~ok).sum()), "test configurations the CV refused", "1"),
                ("evaluation_time", 1e6 * float(np.median(times)) if times else np.nan,
                 "median time of one warm-started ξ and ∂ξ/∂x (Python call included)", "us"),
                ("n_nodes", len(cv.nodes_), "LME nodes of the manifold", "1"),
                ("fit_residual", cv.manifold_.residual_,
                 "rms distance of the training frames to X(ξ_i)", "nm"),
                ("n_training_frames", len(Z), "training frames", "1"),
                ("training_ns", n_steps * 0.002e-3, "unbiased sampling for training", "ns"),
                ("md_ns_per_day", ns_day, "unbiased MD speed (frame reads included)",
                 "ns/day")):
            _v(ds, name, val, long, units)
        ctx.log.info("gradient error %.2e, rigid-motion error %.2e, at most %d Newton steps "
                     "(%d of %d configurations accepted); %.1f µs per evaluation",
                     float(ds["gradient_error"]), float(ds["rigid_motion_error"]),
                     int(ds["max_newton_steps"]), int(ok.sum()), n,
                     float(ds["evaluation_time"]))
        ds.attrs["title"] = "SandCV gradient, invariance and Newton checks"
        return ds
