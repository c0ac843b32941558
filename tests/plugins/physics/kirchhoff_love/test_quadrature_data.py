import numpy as np
import pytest

from pointatlas.basis import BasisFunctions
from pointatlas.errors import InputError
from pointatlas_physics.kirchhoff_love.quadrature_data import (
    ShellQuadrature, concatenate, from_basis)


def _basis(m=3, k=4):
    rng = np.random.default_rng(0)
    indptr = np.arange(m + 1) * k
    indices = np.tile(np.arange(k), m)
    return BasisFunctions(indptr, indices, rng.random(m * k), rng.random((m * k, 2)),
                          rng.random((m * k, 2, 2)))


def test_from_basis_maps_nodes_and_columns():
    bf = _basis()
    T, S = np.ones((3, 2, 3)), np.zeros((3, 2, 2, 3))
    q = from_basis(bf, T, S, np.ones(3), 7, n_nodes=20, node_index=np.array([3, 5, 9, 19]))
    assert q.indices[:4].tolist() == [3, 5, 9, 19]
    assert np.allclose(q.basis[:, 0], bf.values)
    assert np.allclose(q.basis[:, 3], bf.hessians[:, 0, 0])
    assert np.allclose(q.basis[:, 4], 0.5 * (bf.hessians[:, 0, 1] + bf.hessians[:, 1, 0]))
    assert q.group.tolist() == [7, 7, 7] and q.reference.shape == (3, 5, 3)
    both = concatenate([q, q])
    assert both.n_points == 6 and both.indptr[-1] == 24
    assert np.array_equal(both.indices[12:], q.indices)


def test_bad_inputs_raise():
    bf = _basis()
    with pytest.raises(InputError, match="n_nodes"):
        from_basis(bf, np.ones((3, 2, 3)), np.zeros((3, 2, 2, 3)), np.ones(3), 0, n_nodes=2)
    with pytest.raises(InputError, match="order=2"):
        from_basis(BasisFunctions(bf.indptr, bf.indices, bf.values), np.ones((3, 2, 3)),
                   np.zeros((3, 2, 2, 3)), np.ones(3), 0, n_nodes=4)
    with pytest.raises(InputError, match="weights"):
        ShellQuadrature(bf.indptr, bf.indices, np.zeros((12, 6)), np.zeros((3, 5, 3)),
                        np.ones(2), np.zeros(3), 4)
