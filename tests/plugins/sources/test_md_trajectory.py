"""md_trajectory: aligned alanine dipeptide frames as points, and a foreign file refused."""
import numpy as np
import pytest

from pointatlas.errors import InputError
from pointatlas_sources.md_trajectory import MDTrajectory


def test_a_short_run_gives_aligned_heavy_atom_frames():
    cloud = MDTrajectory(n_points=30, stride=20, equilibration=100).load(
        np.random.default_rng(0))
    assert cloud.points.shape == (30, 30)                  # 10 heavy atoms × 3
    frames = cloud.points.reshape(30, 10, 3)
    assert np.allclose(frames.mean(axis=1), 0.0, atol=1e-6)   # centred
    # bonded heavy atoms stay ~0.12–0.16 nm apart (C–N, C–C), nm units
    d = np.linalg.norm(frames[:, 3] - frames[:, 1], axis=1)   # the first peptide bond C–N
    assert np.all((d > 0.11) & (d < 0.17))
    assert cloud.parameters.shape == (30, 2)
    assert np.all(np.abs(cloud.parameters) <= 180)


def test_a_trajectory_of_another_molecule_is_refused(tmp_path):
    import mdtraj

    top = mdtraj.Topology()
    res = top.add_residue("X", top.add_chain())
    for _ in range(7):
        top.add_atom("C", mdtraj.element.carbon, res)
    path = tmp_path / "seven.dcd"
    mdtraj.Trajectory(np.zeros((2, 7, 3), np.float32), top).save_dcd(str(path))
    with pytest.raises(InputError, match="7 atoms, the system 22|cannot read trajectory"):
        MDTrajectory(trajectory=str(path)).load(np.random.default_rng(0))
