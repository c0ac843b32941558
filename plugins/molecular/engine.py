"""The MD engine: OpenMM systems, seeded Langevin contexts and unbiased trajectories.

Langevin dynamics (OpenMM's ``LangevinMiddleIntegrator``) at 300 K, friction 1/ps, 2 fs with
bonds to hydrogen constrained, seeded (integrator noise and initial velocities). Positions in
nm, energies in kJ/mol, times in ps. The alanine dipeptide systems come from openmmtools (no
download); a user's system from a PDB or an Amber prmtop/inpcrd pair via OpenMM's readers.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pointatlas.errors import ConfigError, InputError

#: heavy-atom dihedrals of alanine dipeptide (openmmtools atom order): φ = C-N-CA-C,
#: ψ = N-CA-C-N
PHI, PSI = (4, 6, 8, 14), (6, 8, 14, 16)


@dataclass
class MolecularSystem:
    system: object
    topology: object
    positions: np.ndarray           # (n_atoms, 3) nm

    @property
    def heavy_atoms(self) -> np.ndarray:
        return np.array([a.index for a in self.topology.atoms()
                         if a.element is not None and a.element.symbol != "H"])


def load_system(name: str = "alanine_dipeptide_vacuum", pdb: str | None = None,
                prmtop: str | None = None, inpcrd: str | None = None) -> MolecularSystem:
    """``alanine_dipeptide_vacuum`` / ``alanine_dipeptide_implicit`` (openmmtools, H-bonds
    constrained), or a user's ``prmtop`` + ``inpcrd`` (Amber) or ``pdb`` (amber14 force field,
    no cut-off)."""
    import openmm.app as app
    import openmm.unit as u

    if prmtop or pdb:
        for f in (prmtop, inpcrd, pdb):
            if f and not Path(f).is_file():
                raise InputError(f"molecular input {f} does not exist; give an existing file.")
        if prmtop:
            if not inpcrd:
                raise InputError("a prmtop needs its coordinates: set inpcrd=<file.inpcrd>.")
            top, crd = app.AmberPrmtopFile(prmtop), app.AmberInpcrdFile(inpcrd)
            system = top.createSystem(nonbondedMethod=app.NoCutoff, constraints=app.HBonds)
            pos = crd.getPositions(asNumpy=True).value_in_unit(u.nanometer)
            return MolecularSystem(system, top.topology, np.asarray(pos))
        pdbf = app.PDBFile(pdb)
        ff = app.ForceField("amber14-all.xml")
        system = ff.createSystem(pdbf.topology, nonbondedMethod=app.NoCutoff,
                                 constraints=app.HBonds)
        pos = pdbf.getPositions(asNumpy=True).value_in_unit(u.nanometer)
        return MolecularSystem(system, pdbf.topology, np.asarray(pos))
    from openmmtools import testsystems

    kinds = {"alanine_dipeptide_vacuum": testsystems.AlanineDipeptideVacuum,
             "alanine_dipeptide_implicit": testsystems.AlanineDipeptideImplicit}
    if name not in kinds:
        raise ConfigError(f"unknown molecular system {name!r}; choose one of {sorted(kinds)} "
                          f"or give pdb=… / prmtop=… with inpcrd=….")
    t = kinds[name](constraints=app.HBonds)
    return MolecularSystem(t.system, t.topology,
                           np.asarray(t.positions.value_in_unit(u.nanometer)))


def platform(name: str):
    """The OpenMM platform ``name``, or a one-line error listing the available ones."""
    import openmm as mm

    names = [mm.Platform.getPlatform(i).getName() for i in range(mm.Platform.getNumPlatforms())]
    if name not in names:
        raise ConfigError(f"OpenMM platform {name!r} is not available here; choose one of "
                          f"{names} (engine.platform=…).")
    return mm.Platform.getPlatformByName(name)


def langevin_context(system, positions, seed: int, platform_name: str = "Reference",
                     temperature: float = 300.0, friction: float = 1.0, dt: float = 0.002):
    """(context, integrator): T in K, friction in 1/ps, dt in ps; velocities drawn at T."""
    import openmm as mm
    import openmm.unit as u

    integ = mm.LangevinMiddleIntegrator(temperature * u.kelvin, friction / u.picosecond,
                                        dt * u.picoseconds)
    integ.setRandomNumberSeed(int(seed) % 2**31 or 1)
    ctx = mm.Context(system, integ, platform(platform_name))
    ctx.setPositions(positions * u.nanometer)
    ctx.setVelocitiesToTemperature(temperature * u.kelvin, int(seed) % 2**31 or 1)
    return ctx, integ


def positions_of(ctx, out: np.ndarray | None = None) -> np.ndarray:
    """The context's positions (n_atoms, 3) in nm, into ``out`` if given. Reads the State's
    buffer straight into numpy (OpenMM's ``getPositions(asNumpy=True)`` spends ~15 µs per call
    on ``dir()`` and unit arithmetic, as much as a Reference MD step of alanine dipeptide)."""
    import openmm as mm

    state = ctx.getState(getPositions=True)
    if out is None:
        out = np.empty((ctx.getSystem().getNumParticles(), 3))
    fill = getattr(state, "_getVectorAsNumpy", None)
    if fill is None:  # an OpenMM without the private helper: the public, unit-carrying path
        import openmm.unit as u

        out[:] = state.getPositions(asNumpy=True).value_in_unit(u.nanometer)
    else:
        fill(mm.State.Positions, out)  # OpenMM's internal unit is nm
    return out


def unbiased_frames(mol: MolecularSystem, n_frames: int, stride: int, seed: int,
                    equilibration: int = 5000, platform_name: str = "Reference",
                    temperature: float = 300.0, dt: float = 0.002) -> np.ndarray:
    """(n_frames, n_atoms, 3) positions (nm) every ``stride`` steps after ``equilibration``."""
    ctx, integ = langevin_context(mol.system, mol.positions, seed, platform_name,
                                  temperature, dt=dt)
    integ.step(int(equilibration))
    out = np.empty((n_frames,) + mol.positions.shape)
    for f in range(n_frames):
        integ.step(int(stride))
        out[f] = positions_of(ctx)
    return out


def dihedrals(frames: np.ndarray, quads=(PHI, PSI)) -> np.ndarray:
    """Dihedral angles (frames, len(quads)) in degrees, IUPAC sign convention."""
    f = np.asarray(frames, dtype=np.float64)
    out = np.empty((len(f), len(quads)))
    for k, (a, b, c, d) in enumerate(quads):
        b0, b1, b2 = f[:, a] - f[:, b], f[:, c] - f[:, b], f[:, d] - f[:, c]
        b1n = b1 / np.linalg.norm(b1, axis=1, keepdims=True)
        v = b0 - np.sum(b0 * b1n, axis=1, keepdims=True) * b1n
        w = b2 - np.sum(b2 * b1n, axis=1, keepdims=True) * b1n
        x = np.sum(v * w, axis=1)
        y = np.sum(np.cross(b1n, v) * w, axis=1)
        out[:, k] = np.degrees(np.arctan2(y, x))
    return out
