"""Exploration with a data-driven CV: 2-D SandCV from a short unbiased run, eABF on it, and
the free energy compared against eABF on (φ, ψ) (issue 22's ``sandcv_alanine``).

1. Training: an unbiased Langevin run at ``temperature`` (2 fs, H-bonds constrained;
   ``n_frames`` frames every ``stride`` steps after ``equilibration``), or a user's
   ``trajectory``; heavy atoms superposed by mdtraj, embedded by the ``embedder`` (Isomap,
   d = 2) and parametrised by the ``approximant`` (LME) on ``n_bins`` binned nodes.
2. eABF on ξ = (ξ_1, ξ_2) (:mod:`pointatlas_molecular.eabf_grid`) for ``abf_steps`` steps from
   the last training frame: ``abf_bins`` bins per axis over the box of the LME nodes, λ
   reflected at the nodes' convex hull (the region where ξ is defined), coupling
   k_a = kT / w_a² (λ's thermal spread one bin width w_a), λ's mass such that its period is
   ``lambda_period_steps`` time steps. A step whose projection the CV refuses (outside its
   region, near the focal set) gets no bias; the count is reported and logged as a warning.
3. Reference: eABF on (φ, ψ) (periodic, ``reference_bins`` per axis, k = ``reference_coupling``
   kJ/mol/rad²) for ``reference_steps`` steps; A by CZAR + Poisson integration
   (:mod:`pointatlas_molecular.mean_force_2d`).

Headline figures: ``fraction_unsampled_basin``, the fraction of the biased run's saved
samples in the C7ax/αL basin (0° < φ < 120°; :mod:`pointatlas_molecular.basins` says why
not φ > 0 literally), which the training set must not contain
(``training_fraction_unsampled_basin``); ``first_visit_ps``, the biased time of the first
such sample (NaN: never); ``basin_minimum_error_deg`` per basin, the (φ, ψ) distance between
the minimum of A(ξ) mapped onto (φ, ψ) (the dihedrals of the manifold's configuration X(ξ))
and the reference's minimum in that basin (NaN where A(ξ) does not reach the basin).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.constraints import Interval
from pointatlas.stores_config import stores_config
from pointatlas_studies.reduced_pendulum import _v

KB = 0.0083144626  # kJ/mol/K
NS_PER_STEP = 0.002e-3


@dataclass
class SandCVAlanineSettings:
    system: str = "alanine_dipeptide_vacuum"
    platform: str = "Reference"
    temperature: float = 300.0
    trajectory: Optional[str] = None
    n_frames: int = 2000
    stride: int = 50
    equilibration: int = 5000
    n_bins: int = 12
    newton_tol: float = 1e-10
    min_conditioning: float = 0.1
    abf_steps: int = 125_000
    abf_bins: int = 24
    lambda_period_steps: int = 50
    lambda_friction: float = 10.0
    full_samples: int = 200
    save_every: int = 10
    reference_steps: int = 500_000
    reference_bins: int = 24
    reference_coupling: float = 1000.0
    reference_mass: float = 0.5
    min_count: int = 10
    parameter_constraints: ClassVar[dict] = {
        "temperature": [Interval(float, 0, None, closed="neither")],
        "n_frames": [Interval(int, 20, None)], "stride": [Interval(int, 1, None)],
        "equilibration": [Interval(int, 0, None)], "n_bins": [Interval(int, 4, None)],
        "newton_tol": [Interval(float, 0, 1e-4, closed="right")],
        "min_conditioning": [Interval(float, 0, 1)],
        "abf_steps": [Interval(int, 100, None)], "abf_bins": [Interval(int, 4, None)],
        "lambda_period_steps": [Interval(int, 10, None)],
        "lambda_friction": [Interval(float, 0, None)],
        "full_samples": [Interval(int, 1, None)], "save_every": [Interval(int, 1, None)],
        "reference_steps": [Interval(int, 100, None)],
        "reference_bins": [Interval(int, 8, None)],
        "reference_coupling": [Interval(float, 0, None, closed="neither")],
        "reference_mass": [Interval(float, 0, None, closed="neither")],
        "min_count": [Interval(int, 1, None)]}


def training_frames(self, mol, seed):
    """(frames (N, atoms, 3) nm, unbiased steps run)."""
    from pointatlas_molecular.engine import unbiased_frames

    if self.trajectory:
        from pointatlas_molecular.ensemble import read_trajectory

        return read_trajectory(self.trajectory, mol.topology, len(mol.positions)), 0
    return (unbiased_frames(mol, self.n_frames, self.stride, seed, self.equilibration,
                            self.platform, self.temperature),
            self.equilibration + self.n_frames * self.stride)


@stores_config
class SandCVAlanine:
    """2-D SandCV of alanine dipeptide from a short unbiased run, eABF on it, compared with
    eABF on (φ, ψ)."""

    Config = SandCVAlanineSettings
    description: ClassVar[str] = ("Exploration with SandCV: eABF on a 2-D Isomap + LME CV "
                                  "learnt from a short unbiased run of alanine dipeptide, "
                                  "against eABF on (φ, ψ).")

    @staticmethod
    def report_figures(ds):
        from pointatlas_studies.abf_figures import cv_map_figure, phipsi_map_figure

        return [("Free energy on (φ, ψ) from eABF on (φ, ψ); training and SandCV-biased "
                 "samples; minima of A(ξ) mapped onto (φ, ψ)", phipsi_map_figure(ds)),
                ("Free energy along the SandCV ξ = (ξ₁, ξ₂) from eABF on ξ",
                 cv_map_figure(ds))]

    def run(self, ctx):
        import xarray as xr

        from pointatlas_molecular.basins import (BASINS, angular_distance, basin_minimum,
                                                 grid_dihedrals, in_basin)
        from pointatlas_molecular.biased_md import run_eabf
        from pointatlas_molecular.dihedral_cv import DihedralPairCV
        from pointatlas_molecular.eabf_grid import EABFGrid
        from pointatlas_molecular.engine import PHI, PSI, dihedrals, load_system
        from pointatlas_molecular.training import train_sandcv

        mol = load_system(self.system)
        heavy = mol.heavy_atoms
        kT = KB * self.temperature
        seeds = ctx.rng("md").integers(1, 2**31 - 1, 3)
        with ctx.timed("training_md"):
            t0 = time.perf_counter()
            frames, n_train_steps = training_frames(self, mol, int(seeds[0]))
            train_rate = n_train_steps / (time.perf_counter() - t0)
        with ctx.timed("training"):
            cv, Z, Q = train_sandcv(frames, heavy, ctx.plugin("embedder"),
                                    ctx.plugin("approximant"), self.n_bins, self.newton_tol,
                                    self.min_conditioning)
        train_pp = dihedrals(frames)
        lo, hi = cv.nodes_.min(axis=0), cv.nodes_.max(axis=0)
        w = (hi - lo) / self.abf_bins
        k = kT / w ** 2
        mass = k * (self.lambda_period_steps * 0.002 / (2 * np.pi)) ** 2
        start = frames[-1]
        e = EABFGrid(lo, hi, self.abf_bins, k=k, mass=mass, kT=kT,
                     friction=self.lambda_friction, full_samples=self.full_samples,
                     region=cv.hull_, lam=cv(start[heavy]).xi)
        log = lambda name, n: (lambda s: ctx.log.info("%s step %d of %d", name, s, n))  # noqa
        with ctx.timed("abf_sandcv"):
            run = run_eabf(mol, cv, heavy, e, self.abf_steps, int(seeds[1]),
                           platform=self.platform, save_every=self.save_every,
                           positions=start, save_atoms=np.arange(len(mol.positions)),
                           progress=log("eABF on ξ", self.abf_steps))
        if run.n_refused:
            ctx.log.warning("the SandCV refused %d of %d steps (first at step %d): their "
                            "configurations project outside the parametrised region or "
                            "near its focal set; no bias was applied there", run.n_refused,
                            self.abf_steps, run.first_refused_step)
        biased_pp = dihedrals(run.frames)
        A_xi, _ = e.free_energy(self.min_count)
        cells = [e.centres(0), e.centres(1)]
        heavy_pos = {a: i for i, a in enumerate(heavy)}
        quads = [tuple(heavy_pos[a] for a in q) for q in (PHI, PSI)]
        mapped = grid_dihedrals(cv.manifold_, cells, quads)

        pair = DihedralPairCV.of(PHI, PSI)
        r = EABFGrid([-np.pi] * 2, [np.pi] * 2, self.reference_bins,
                     k=self.reference_coupling, mass=self.reference_mass, kT=kT,
                     friction=self.lambda_friction, full_samples=self.full_samples,
                     periods=(2 * np.pi, 2 * np.pi), lam=pair(mol.positions[pair.atoms]).xi)
        with ctx.timed("abf_phi_psi"):
            ref_run = run_eabf(mol, pair, pair.atoms, r, self.reference_steps, int(seeds[2]),
                               platform=self.platform, save_every=self.save_every,
                               save_atoms=pair.atoms,
                               progress=log("eABF on (φ, ψ)", self.reference_steps))
        A_ref, _ = r.free_energy(self.min_count)
        ang = [np.degrees(r.centres(0)), np.degrees(r.centres(1))]
        PH, PS = np.meshgrid(*ang, indexing="ij")

        in_new = in_basin(biased_pp[:, 0], "C7ax")
        dt_save = self.save_every * 0.002
        errors, ref_min, cv_min = [], [], []
        for name in BASINS:
            p_ref, _ = basin_minimum(A_ref, PH, PS, name)
            p_cv, _ = basin_minimum(A_xi, mapped[..., 0], mapped[..., 1], name)
            ref_min.append(p_ref)
            cv_min.append(p_cv)
            errors.append(angular_distance(p_cv, p_ref) if np.isfinite(p_cv[0]) else np.nan)
        ds = xr.Dataset(coords={
            "xi1": ("xi1", cells[0], {"long_name": "SandCV ξ₁ (bin centre)", "units": "1"}),
            "xi2": ("xi2", cells[1], {"long_name": "SandCV ξ₂ (bin centre)", "units": "1"}),
            "phi": ("phi", ang[0], {"long_name": "backbone dihedral φ (bin centre)",
                                    "units": "degree"}),
            "psi": ("psi", ang[1], {"long_name": "backbone dihedral ψ (bin centre)",
                                    "units": "degree"}),
            "basin": ("basin", list(BASINS), {"long_name": "conformational basin", "units": "1"}),
            "angle": ("angle", ["phi", "psi"], {"long_name": "backbone dihedral", "units": "1"})})
        samples = lambda a: ("sample", "angle") if a.ndim == 2 else ("sample",)  # noqa: E731
        for name, val, long, units, dims in (
                ("free_energy_cv", A_xi, "A(ξ) from eABF on the SandCV (CZAR, Poisson)",
                 "kJ/mol", ("xi1", "xi2")),
                ("cv_samples", e.z_count.reshape(e.n_bins), "eABF samples of ξ per cell", "1",
                 ("xi1", "xi2")),
                ("cv_cell_dihedrals", mapped, "(φ, ψ) of the manifold's X(ξ) at each cell",
                 "degree", ("xi1", "xi2", "angle")),
                ("free_energy_phi_psi", A_ref, "A(φ, ψ) from eABF on (φ, ψ) (CZAR, Poisson)",
                 "kJ/mol", ("phi", "psi")),
                ("phi_psi_samples", r.z_count.reshape(r.n_bins), "eABF samples per cell", "1",
                 ("phi", "psi")),
                ("reference_minimum", np.array(ref_min), "minimum of A(φ, ψ) in the basin",
                 "degree", ("basin", "angle")),
                ("sandcv_minimum", np.array(cv_min), "minimum of A(ξ) in the basin, mapped "
                 "onto (φ, ψ)", "degree", ("basin", "angle")),
                ("basin_minimum_error_deg", np.array(errors), "(φ, ψ) distance between the "
                 "SandCV's and the reference's minimum", "degree", ("basin",))):
            _v(ds, name, val, long, units, dims)
        ds["training_dihedrals"] = (("training_frame", "angle"), train_pp,
                                    {"long_name": "(φ, ψ) of the training frames",
                                     "units": "degree"})
        ds["biased_dihedrals"] = (("biased_sample", "angle"), biased_pp,
                                  {"long_name": f"(φ, ψ) of the SandCV-biased run every "
                                                f"{dt_save:g} ps", "units": "degree"})
        first = float(np.argmax(in_new) * dt_save) if in_new.any() else np.nan
        for name, val, long, units in (
                ("fraction_unsampled_basin", float(in_new.mean()), "fraction of the "
                 "SandCV-biased samples in C7ax/αL (0° < φ < 120°)", "1"),
                ("training_fraction_unsampled_basin",
                 float(in_basin(train_pp[:, 0], "C7ax").mean()),
                 "fraction of the training frames in C7ax/αL", "1"),
                ("first_visit_ps", first, "biased time of the first C7ax/αL sample", "ps"),
                ("n_refused", run.n_refused, "biased steps the SandCV refused (no bias)", "1"),
                ("max_newton_steps", run.newton_steps_max, "most Newton steps of a "
                 "projection in the biased run", "1"),
                ("n_training_frames", len(Z), "training frames", "1"),
                ("n_nodes", len(cv.nodes_), "LME nodes of the manifold", "1"),
                ("training_ns", n_train_steps * NS_PER_STEP, "unbiased sampling", "ns"),
                ("abf_ns", self.abf_steps * NS_PER_STEP, "eABF on the SandCV", "ns"),
                ("reference_ns", self.reference_steps * NS_PER_STEP, "eABF on (φ, ψ)", "ns"),
                ("training_ns_per_day", train_rate * NS_PER_STEP * 86400
                 if n_train_steps else np.nan, "unbiased MD speed", "ns/day"),
                ("abf_ns_per_day", run.steps_per_second * NS_PER_STEP * 86400,
                 "SandCV-biased MD speed", "ns/day"),
                ("reference_ns_per_day", ref_run.steps_per_second * NS_PER_STEP * 86400,
                 "(φ, ψ)-biased MD speed", "ns/day")):
            _v(ds, name, val, long, units)
        ctx.log.info("SandCV eABF: %.3f of the samples in C7ax/αL (first at %s ps); basin "
                     "minima off by %s degrees; %d refused steps",
                     float(in_new.mean()), first, np.round(errors, 1), run.n_refused)
        ds.attrs["title"] = "SandCV exploration of alanine dipeptide against eABF on (phi, psi)"
        return ds
