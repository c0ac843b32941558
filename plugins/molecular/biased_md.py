"""Biased MD on OpenMM: each step the CV and its gradient are computed from the positions in
Python and the coupling force enters through a ``CustomExternalForce`` whose per-particle
parameters (fx, fy, fz) are updated in the context, so any platform works.

Energy of the external force: −(fx x + fy y + fz z) per CV atom, i.e. the force (fx, fy, fz)
kJ/mol/nm, set to −k (ξ − λ) ∂ξ/∂r at the step's starting positions (LangevinMiddle
evaluates forces once per step, at those positions). A step whose CV is refused (projection
outside the parametrised region, ill-conditioned, …) gets no bias force and is counted;
λ then feels no coupling either.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from .engine import langevin_context, positions_of
from .eabf import EABF


@dataclass
class BiasedRun:
    """Per saved step: ξ, λ (scalars for a 1-D :class:`.eabf.EABF`, else (d,)), the positions
    of ``save_atoms`` (nm); counts and speed."""
    xi: np.ndarray
    lam: np.ndarray
    frames: np.ndarray
    n_refused: int
    first_refused_step: int
    steps_per_second: float
    newton_steps_max: int


def coupling_force(cv_atoms):
    """A CustomExternalForce on ``cv_atoms`` with zeroed per-particle (fx, fy, fz)."""
    import openmm as mm

    f = mm.CustomExternalForce("-(fx*x+fy*y+fz*z)")
    for name in ("fx", "fy", "fz"):
        f.addPerParticleParameter(name)
    for a in cv_atoms:
        f.addParticle(int(a), [0.0, 0.0, 0.0])
    f.setForceGroup(31)
    return f


def run_eabf(mol, cv, cv_atoms, eabf, n_steps: int, seed: int, *, platform="Reference",
             dt=0.002, save_every=10, save_atoms=None, positions=None, progress=None):
    """``n_steps`` of eABF-biased Langevin MD on ``cv`` (SandCV, DihedralCV, DihedralPairCV) of
    the atoms ``cv_atoms`` with ``eabf`` an :class:`.eabf.EABF` (ξ_0 only) or an
    :class:`.eabf_grid.EABFGrid` (its ``dim`` first components of ξ); returns a
    :class:`BiasedRun`. λ starts at ξ of the start configuration, which must have a
    trustworthy CV inside the eABF range."""
    import copy

    from pointatlas.errors import PointatlasError

    eabf.check_time_step(dt)
    system = copy.deepcopy(mol.system)
    force = coupling_force(cv_atoms)
    system.addForce(force)
    start = mol.positions if positions is None else positions
    ctx, integ = langevin_context(system, start, seed, platform, dt=dt)
    rng = np.random.default_rng(seed)
    save_atoms = np.arange(system.getNumParticles()) if save_atoms is None else save_atoms
    n_save = n_steps // save_every
    scalar = isinstance(eabf, EABF)
    d = 1 if scalar else eabf.dim
    comp = (lambda xi: float(xi[0])) if scalar else (lambda xi: xi[:d])  # noqa: E731
    shape = (n_save,) if scalar else (n_save, d)
    xi_out, lam_out = np.empty(shape), np.empty(shape)
    frames = np.empty((n_save, len(save_atoms), 3), dtype=np.float32)
    x0 = positions_of(ctx)[cv_atoms]
    v0 = cv(x0)
    if not v0.ok:
        raise PointatlasError(f"the starting configuration has no trustworthy CV value "
                              f"({v0.reason}); start from a configuration the CV was trained "
                              f"near.")
    xi0 = comp(v0.xi)
    inside = eabf.bin(xi0) >= 0 and (scalar or eabf.inside(xi0))
    if not inside:
        raise PointatlasError(f"the CV range [{eabf.lower}, {eabf.upper}] excludes the "
                              f"starting configuration (ξ = {np.round(xi0, 4)}); widen the "
                              f"range or start inside it.")
    eabf.lam, eabf.vel = (xi0, 0.0) if scalar else (xi0.copy(), np.zeros(d))  # no kick
    predicts = hasattr(cv, "predict")
    prev = None
    refused, first_refused, newton_max = 0, -1, 0
    x_prev = None
    atoms = [int(a) for a in cv_atoms]
    zero = [0.0, 0.0, 0.0]
    pos = np.empty((system.getNumParticles(), 3))
    t0 = time.perf_counter()
    for s in range(n_steps):
        positions_of(ctx, pos)
        if not math.isfinite(float(pos.sum())):
            raise PointatlasError(
                f"biased MD blew up at step {s} (non-finite positions): lower the coupling "
                f"k or the time step, or raise the extended variable's mass.")
        x = pos[cv_atoms]
        start_xi = None
        if prev is not None and prev.ok:
            start_xi = cv.predict(prev, x_prev, x) if predicts else prev.xi
        v = cv(x, start_xi)
        if v.ok:
            newton_max = max(newton_max, v.steps)
            xi = comp(v.xi)
            c = eabf.coupling(xi)
            g = v.gradient
            fvec = -c * g[0] if scalar else -(c @ g[:d].reshape(d, -1)).reshape(-1, 3)
            for i, row in enumerate(fvec.tolist()):
                force.setParticleParameters(i, atoms[i], row)
            eabf.step(xi, rng, dt)
        else:
            refused += 1
            first_refused = s if first_refused < 0 else first_refused
            for i in range(len(atoms)):
                force.setParticleParameters(i, atoms[i], zero)
        force.updateParametersInContext(ctx)
        if s % save_every == 0 and s // save_every < n_save:
            j = s // save_every
            xi_out[j] = comp(v.xi) if v.ok else np.nan
            lam_out[j] = eabf.lam
            frames[j] = pos[save_atoms]
        prev, x_prev = v, x
        integ.step(1)
        if progress is not None and s % 10000 == 0:
            progress(s)
    rate = n_steps / (time.perf_counter() - t0)
    return BiasedRun(xi_out, lam_out, frames, refused, first_refused, rate, newton_max)
