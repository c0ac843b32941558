"""ABF on φ of alanine dipeptide against umbrella sampling + MBAR (issue 22's ``abf_phi``).

Both in the same force field and thermostat (:mod:`pointatlas_molecular.engine`): Langevin
300 K, 2 fs, H-bonds constrained. ABF: the extended-system variant with the CZAR estimator
(:mod:`pointatlas_molecular.eabf`; why this ABF: there), ``abf_steps`` steps, λ coupled by
``coupling`` kJ/mol/rad², ``n_bins`` bins over [−π, π). Its statistical error: the run after
the first ``discard`` fraction split into ``n_blocks`` blocks, the CZAR profile of each
(saved every ``save_every`` steps), standard error of the block profiles (aligned on their
mean over the common bins). Umbrella sampling: ``n_windows`` windows, κ = ``kappa``,
``window_steps`` each after ``window_equilibration`` (:mod:`pointatlas_molecular.umbrella`),
MBAR with analytical errors. ``rms_difference``: RMS of A_ABF − A_US over the bins both
estimate, after removing the mean difference (free energies are defined up to a constant).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from pointatlas.constraints import Interval
from pointatlas.stores_config import stores_config
from pointatlas_studies.reduced_pendulum import _v

KB = 0.0083144626  # kJ/mol/K


@dataclass
class ABFPhiSettings:
    system: str = "alanine_dipeptide_vacuum"
    platform: str = "Reference"
    temperature: float = 300.0
    abf_steps: int = 500_000
    coupling: float = 1000.0
    lambda_mass: float = 0.5
    lambda_friction: float = 10.0
    full_samples: int = 200
    n_bins: int = 72
    save_every: int = 10
    n_blocks: int = 5
    discard: float = 0.1
    n_windows: int = 36
    kappa: float = 200.0
    window_steps: int = 25_000
    window_equilibration: int = 2_500
    parameter_constraints: ClassVar[dict] = {
        "temperature": [Interval(float, 0, None, closed="neither")],
        "abf_steps": [Interval(int, 100, None)],
        "coupling": [Interval(float, 0, None, closed="neither")],
        "lambda_mass": [Interval(float, 0, None, closed="neither")],
        "lambda_friction": [Interval(float, 0, None)],
        "full_samples": [Interval(int, 1, None)], "n_bins": [Interval(int, 8, None)],
        "save_every": [Interval(int, 1, None)], "n_blocks": [Interval(int, 2, None)],
        "discard": [Interval(float, 0, 0.9)], "n_windows": [Interval(int, 4, None)],
        "kappa": [Interval(float, 0, None, closed="neither")],
        "window_steps": [Interval(int, 10, None)],
        "window_equilibration": [Interval(int, 0, None)]}


def block_profiles(z, lam, e, kT, n_blocks, discard):
    """CZAR profiles of consecutive blocks of the saved (ξ, λ) series: (n_blocks, n_bins)."""
    from pointatlas_molecular.eabf import czar_gradient, integrate_gradient, wrap

    start = int(discard * len(z))
    out = []
    for zb, lb in zip(np.array_split(z[start:], n_blocks), np.array_split(lam[start:], n_blocks)):
        ok = np.isfinite(zb)
        zb, lb = zb[ok], lb[ok]
        b = np.floor((wrap(zb - e.lower, e.period) % e.period) / e.width).astype(int)
        b = np.clip(b, 0, e.n_bins - 1)
        cnt = np.bincount(b, minlength=e.n_bins)
        s = np.bincount(b, weights=wrap(lb - zb, e.period), minlength=e.n_bins)
        g = czar_gradient(cnt, s, e.width, e.k, kT, True, min_count=5)
        out.append(integrate_gradient(g, e.width, True)[0])
    return np.array(out)


def aligned_rms(a, b):
    """RMS of a − b over bins where both are finite, after removing the mean difference."""
    ok = np.isfinite(a) & np.isfinite(b)
    d = a[ok] - b[ok]
    return float(np.sqrt(np.mean((d - d.mean()) ** 2))), int(ok.sum())


@stores_config
class ABFPhi:
    """eABF on φ of alanine dipeptide against umbrella sampling + MBAR."""

    Config = ABFPhiSettings
    description: ClassVar[str] = ("Free energy along φ of alanine dipeptide: eABF (CZAR) "
                                  "against umbrella sampling with MBAR, with errors.")

    @staticmethod
    def report_figures(ds):
        from pointatlas_studies.abf_figures import profile_figure

        return [("Free energy along φ: eABF (CZAR) and umbrella sampling + MBAR, "
                 "bands ±2 standard errors", profile_figure(ds, "phi"))]

    def run(self, ctx):
        import xarray as xr

        from pointatlas_molecular.biased_md import run_eabf
        from pointatlas_molecular.dihedral_cv import DihedralCV
        from pointatlas_molecular.eabf import EABF, czar_gradient, integrate_gradient
        from pointatlas_molecular.engine import PHI, load_system
        from pointatlas_molecular.umbrella import mbar_profile, umbrella_samples

        mol = load_system(self.system)
        kT = KB * self.temperature
        seeds = ctx.rng("md").integers(1, 2**31 - 1, 2)
        atoms = np.array(PHI)
        e = EABF(-np.pi, np.pi, self.n_bins, k=self.coupling, mass=self.lambda_mass, kT=kT,
                 friction=self.lambda_friction, full_samples=self.full_samples,
                 period=2 * np.pi, lam=float(DihedralCV(atoms)(mol.positions[atoms]).xi[0]))
        with ctx.timed("abf"):
            run = run_eabf(mol, DihedralCV(atoms), atoms, e, self.abf_steps, int(seeds[0]),
                           platform=self.platform, save_every=self.save_every,
                           save_atoms=atoms,
                           progress=lambda s: ctx.log.info("ABF step %d of %d", s,
                                                           self.abf_steps))
        g = czar_gradient(e.z_count, e.z_lam_sum, e.width, e.k, kT, True)
        A_abf, closure = integrate_gradient(g, e.width, True)
        blocks = block_profiles(run.xi, run.lam, e, kT, self.n_blocks, self.discard)
        ref = np.nanmean(blocks, axis=0)
        blocks = blocks - np.nanmean(blocks - ref, axis=1, keepdims=True)
        dA_abf = np.nanstd(blocks, axis=0, ddof=1) / np.sqrt(self.n_blocks)
        centres = np.linspace(-np.pi, np.pi, self.n_windows, endpoint=False)
        with ctx.timed("umbrella"):
            samples, us_rate = umbrella_samples(
                mol, atoms, centres, self.kappa, self.window_steps, int(seeds[1]),
                equilibration=self.window_equilibration, platform=self.platform)
        edges = np.linspace(-np.pi, np.pi, self.n_bins + 1)
        with ctx.timed("mbar"):
            A_us, dA_us, N_k = mbar_profile(samples, centres, self.kappa, kT, edges)
        rms, n_common = aligned_rms(A_abf, A_us)
        ok = np.isfinite(A_abf) & np.isfinite(A_us)
        A_abf_al = A_abf - np.mean(A_abf[ok] - A_us[ok]) if ok.any() else A_abf
        ds = xr.Dataset(coords={
            "phi": ("phi", np.degrees(e.centres()), {"long_name": "backbone dihedral φ "
                                                    "(bin centre)", "units": "degree"}),
            "window": ("window", np.degrees(centres), {"long_name": "umbrella centre φ_k",
                                                      "units": "degree"})})
        ns = lambda steps: steps * 0.002e-3  # noqa: E731
        for name, val, long, units, dims in (
                ("free_energy_abf", A_abf_al, "A(φ) from eABF (CZAR), aligned on umbrella",
                 "kJ/mol", ("phi",)),
                ("free_energy_abf_error", dA_abf, "standard error of A_ABF (block averages)",
                 "kJ/mol", ("phi",)),
                ("free_energy_umbrella", A_us, "A(φ) from umbrella sampling + MBAR",
                 "kJ/mol", ("phi",)),
                ("free_energy_umbrella_error", dA_us, "MBAR analytical standard error",
                 "kJ/mol", ("phi",)),
                ("abf_samples", e.z_count, "ABF samples of ξ = φ per bin", "1", ("phi",)),
                ("window_samples", N_k, "decorrelated samples per window", "1", ("window",)),
                ("rms_difference", rms, "RMS of A_ABF − A_US over the common bins (mean "
                 "difference removed)", "kJ/mol", ()),
                ("n_common_bins", n_common, "bins both methods estimate", "1", ()),
                ("closure_error", closure, "mean of the CZAR gradient over the period", 
                 "kJ/mol/rad", ()),
                ("max_abf_error", float(np.nanmax(dA_abf)), "largest ABF standard error",
                 "kJ/mol", ()),
                ("max_umbrella_error", float(np.nanmax(dA_us)), "largest MBAR standard error",
                 "kJ/mol", ()),
                ("abf_ns", ns(self.abf_steps), "ABF sampling", "ns", ()),
                ("umbrella_ns", ns(self.n_windows * (self.window_steps
                                                     + self.window_equilibration)),
                 "umbrella sampling (all windows)", "ns", ()),
                ("abf_ns_per_day", ns(run.steps_per_second) * 86400, "biased MD speed",
                 "ns/day", ()),
                ("umbrella_ns_per_day", ns(us_rate) * 86400, "umbrella MD speed", "ns/day",
                 ())):
            _v(ds, name, val, long, units, dims)
        ctx.log.info("eABF on φ against umbrella + MBAR: RMS %.2f kJ/mol over %d bins "
                     "(ABF %.2f ns at %.0f ns/day, umbrella %.2f ns)", rms, n_common,
                     ns(self.abf_steps), ns(run.steps_per_second) * 86400,
                     float(ds["umbrella_ns"]))
        ds.attrs["title"] = "ABF on phi against umbrella sampling + MBAR"
        return ds
