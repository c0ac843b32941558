"""The training ensemble: frames of the CV atoms superposed by mdtraj (Kabsch), as points in
R^D (D = 3 × CV atoms, nm), and the checks a trajectory must pass before it trains a CV."""
from __future__ import annotations

import numpy as np

from pointatlas.errors import InputError


def read_trajectory(path: str, topology, n_atoms: int) -> np.ndarray:
    """Positions (frames, atoms, 3) in nm of a DCD/XTC/HDF5/… file read by mdtraj; refuses a
    trajectory whose atom count does not match the system's."""
    import mdtraj

    top = mdtraj.Topology.from_openmm(topology)
    try:
        traj = mdtraj.load(path, top=top)
    except (OSError, ValueError) as err:
        raise InputError(f"cannot read trajectory {path} with the system's topology "
                         f"({n_atoms} atoms): {str(err).splitlines()[0]}; give a trajectory "
                         f"of this system.") from None
    if traj.n_atoms != n_atoms:
        raise InputError(f"trajectory {path} has {traj.n_atoms} atoms, the system {n_atoms}: "
                         f"the topology does not match; give a trajectory of this system.")
    return np.asarray(traj.xyz, dtype=np.float64)


def aligned(frames: np.ndarray, atoms: np.ndarray, topology=None, reference: int = 0):
    """(Z (frames, len(atoms), 3), reference (len(atoms), 3)): the CV atoms of every frame
    superposed on frame ``reference`` by mdtraj's Kabsch superposition, centred at the
    origin (uniform weights)."""
    import mdtraj

    frames = np.asarray(frames, dtype=np.float32)
    sub = frames[:, atoms]
    top = mdtraj.Topology()
    chain = top.add_chain()
    res = top.add_residue("CV", chain)
    for _ in atoms:
        top.add_atom("C", mdtraj.element.carbon, res)
    traj = mdtraj.Trajectory(sub, top)
    traj.superpose(traj, frame=reference)
    Z = np.asarray(traj.xyz, dtype=np.float64)
    Z -= Z.mean(axis=1, keepdims=True)
    return Z, Z[reference].copy()


def check_training(n_frames: int, n_components: int, n_neighbors: int) -> None:
    """Enough frames for the embedding dimension and the neighbour graph."""
    need = max(n_neighbors + 1, 10 * n_components + 1)
    if n_frames < need:
        raise InputError(f"{n_frames} training frames are too few for d = {n_components} "
                         f"with {n_neighbors} neighbours (need at least {need}); sample "
                         f"more frames or lower embedder.n_components / n_neighbors.")
