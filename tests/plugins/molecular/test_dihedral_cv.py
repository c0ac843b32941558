"""φ and its analytic gradient against the IUPAC dihedral and central differences."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pointatlas_molecular.dihedral_cv import DihedralCV
from pointatlas_molecular.engine import dihedrals


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 100_000))
def test_value_and_gradient(seed):
    x = np.random.default_rng(seed).normal(size=(4, 3))
    v = DihedralCV([0, 1, 2, 3])(x)
    assert np.isclose(np.degrees(v.xi[0]), dihedrals(x[None], [(0, 1, 2, 3)])[0, 0])
    h, fd = 1e-6, np.empty((4, 3))
    for i in range(4):
        for a in range(3):
            e = np.zeros((4, 3))
            e[i, a] = h
            d = DihedralCV([0, 1, 2, 3])(x + e).xi[0] - DihedralCV([0, 1, 2, 3])(x - e).xi[0]
            fd[i, a] = (d + np.pi) % (2 * np.pi) - np.pi
    fd /= 2 * h
    assert np.max(np.abs(fd - v.gradient[0])) < 1e-6 * max(1.0, np.max(np.abs(fd)))


def test_a_trans_chain_is_180_degrees():
    x = np.array([[0.0, 1, 0], [0, 0, 0], [1, 0, 0], [1, -1, 0]])
    assert np.isclose(abs(DihedralCV([0, 1, 2, 3])(x).xi[0]), np.pi)


def test_pair_of_dihedrals_sharing_atoms():
    """(φ, ψ) over the union of their atoms: values and gradients are the single dihedrals'
    scattered into the union, zero on atoms a dihedral does not involve."""
    from pointatlas_molecular.dihedral_cv import DihedralPairCV

    full = np.random.default_rng(3).normal(size=(20, 3))
    q1, q2 = (4, 6, 8, 14), (6, 8, 14, 16)
    pair = DihedralPairCV.of(q1, q2)
    assert list(pair.atoms) == [4, 6, 8, 14, 16]
    v = pair(full[pair.atoms])
    ref = dihedrals(full[None], [q1, q2])[0]
    assert np.allclose(np.degrees(v.xi), ref)
    g1 = DihedralCV(np.arange(4))(full[list(q1)]).gradient[0]
    assert np.allclose(v.gradient[0, :4], g1) and np.all(v.gradient[0, 4] == 0)
    g2 = DihedralCV(np.arange(4))(full[list(q2)]).gradient[0]
    assert np.allclose(v.gradient[1, 1:], g2) and np.all(v.gradient[1, 0] == 0)
