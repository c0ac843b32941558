"""Umbrella sampling on a dihedral with MBAR (pymbar): the independent reference for ABF.

Windows at φ_k (rad) with the periodic harmonic restraint ½ κ wrap(φ − φ_k)² (OpenMM
``CustomTorsionForce``, κ in kJ/mol/rad²), swept in order from one window's last state to
the next; φ saved every ``every`` steps after ``equilibration``, subsampled by each window's
statistical inefficiency (pymbar.timeseries), then the free-energy profile on the bins by
MBAR's histogram FES with analytical uncertainties (Shirts & Chodera, J. Chem. Phys. 129
(2008) 124105).
"""
from __future__ import annotations

import copy
import time

import numpy as np

from .eabf import wrap
from .engine import dihedrals, langevin_context, positions_of


def umbrella_samples(mol, atoms, centres, kappa, n_steps, seed, *, equilibration=5000,
                     every=10, platform="Reference", dt=0.002):
    """(φ samples per window (list of arrays, rad), steps per second)."""
    import openmm as mm

    system = copy.deepcopy(mol.system)
    f = mm.CustomTorsionForce("0.5*kappa*dp^2; dp = d - 2*pi*floor((d + pi)/(2*pi)); "
                              "d = theta - phi0; pi = 3.141592653589793")
    f.addGlobalParameter("kappa", float(kappa))
    f.addGlobalParameter("phi0", float(centres[0]))
    f.addTorsion(*[int(a) for a in atoms], [])
    system.addForce(f)
    ctx, integ = langevin_context(system, mol.positions, seed, platform, dt=dt)
    out = []
    t0 = time.perf_counter()
    quad = [tuple(range(4))]
    for c in centres:
        ctx.setParameter("phi0", float(c))
        integ.step(int(equilibration))
        n = int(n_steps) // every
        phi = np.empty(n)
        for j in range(n):
            integ.step(every)
            phi[j] = np.radians(dihedrals(positions_of(ctx)[list(atoms)][None], quad)[0, 0])
        out.append(phi)
    rate = len(centres) * (equilibration + n_steps) / (time.perf_counter() - t0)
    return out, rate


def mbar_profile(samples, centres, kappa, kT, edges):
    """(A per bin (kJ/mol, minimum 0), its standard error, samples kept per window) by MBAR
    on decorrelated samples; bins are [edges[i], edges[i+1]) in rad."""
    import pymbar
    from pymbar import timeseries

    kept = []
    for s in samples:
        idx = timeseries.subsample_correlated_data(s)
        kept.append(s[idx])
    N_k = np.array([len(s) for s in kept])
    x = np.concatenate(kept)
    K = len(centres)
    u_kn = np.empty((K, len(x)))
    for k, c in enumerate(centres):
        u_kn[k] = 0.5 * kappa * wrap(x - c, 2 * np.pi) ** 2 / kT
    fes = pymbar.FES(u_kn, N_k, verbose=False)
    fes.generate_fes(np.zeros(len(x)), x, fes_type="histogram",
                     histogram_parameters={"bin_edges": np.asarray(edges)})
    centres_b = 0.5 * (edges[1:] + edges[:-1])
    res = fes.get_fes(centres_b, reference_point="from-lowest",
                      uncertainty_method="analytical")
    A = np.asarray(res["f_i"], dtype=float) * kT
    dA = np.asarray(res["df_i"], dtype=float) * kT
    A = A - np.nanmin(A)
    return A, dA, N_k
