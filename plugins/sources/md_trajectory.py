"""Conformations of a molecule as points in R^D (D = 3 × CV atoms, nm): the training ensemble
of SandCV (issue 22), from a trajectory file or a short unbiased run.

The frames' CV atoms (heavy atoms by default) are superposed by mdtraj (Kabsch) on the first
frame and centred; each frame is one point. ``trajectory`` (DCD/XTC/HDF5/…, read by mdtraj
with the system's topology, refused if the atoms do not match) or else ``n_points`` frames
(one point each) every ``stride`` steps of Langevin MD (300 K, 2 fs, H-bonds constrained) after
``equilibration``, seeded from the run seed. For alanine dipeptide the backbone dihedrals
(φ, ψ) in degrees are the points' ``parameters``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.constraints import Interval, Options
from pointatlas.pointcloud import PointCloud
from pointatlas.stores_config import stores_config


@stores_config
class MDTrajectory:
    """Aligned conformations of a molecule from a trajectory file or a short MD run."""

    @dataclass
    class Config:
        system: str = "alanine_dipeptide_vacuum"
        trajectory: Optional[str] = None
        atoms: str = "heavy"
        n_points: int = 2000
        stride: int = 50
        equilibration: int = 5000
        platform: str = "Reference"

        parameter_constraints: ClassVar[dict[str, list]] = {
            "atoms": [Options(("heavy", "all"))], "n_points": [Interval(int, 2, None)],
            "stride": [Interval(int, 1, None)], "equilibration": [Interval(int, 0, None)]}

    description: ClassVar[str] = ("Conformations of a molecule (aligned CV atoms, nm) from a "
                                  "trajectory file or a short unbiased OpenMM run.")

    def load(self, rng: np.random.Generator) -> PointCloud:
        from pointatlas_molecular.engine import dihedrals, load_system, unbiased_frames
        from pointatlas_molecular.ensemble import aligned, read_trajectory

        mol = load_system(self.system)
        if self.trajectory:
            frames = read_trajectory(self.trajectory, mol.topology, len(mol.positions))
            how = f"trajectory {self.trajectory}"
        else:
            seed = int(rng.integers(1, 2**31 - 1))
            frames = unbiased_frames(mol, self.n_points, self.stride, seed, self.equilibration,
                                     self.platform)
            how = (f"unbiased Langevin MD, 300 K, 2 fs, {self.n_points} frames every "
                   f"{self.stride} steps after {self.equilibration}")
        atoms = mol.heavy_atoms if self.atoms == "heavy" else np.arange(len(mol.positions))
        Z, _ = aligned(frames, atoms)
        params = dihedrals(frames) if self.system.startswith("alanine_dipeptide") else None
        return PointCloud(points=Z.reshape(len(Z), -1), parameters=params,
                          name="md_trajectory",
                          info={"how": how, "atoms": self.atoms, "n_atoms": int(len(atoms)),
                                "points_in_source": int(len(frames)),
                                "points_used": int(len(frames))})
