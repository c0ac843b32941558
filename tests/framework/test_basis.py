"""BasisFunctions row subsets and renumbering keep every row intact."""
import numpy as np

from pointatlas.basis import BasisFunctions


def _basis():
    indptr = np.array([0, 2, 3, 6])
    indices = np.array([0, 1, 2, 0, 1, 2])
    values = np.array([0.4, 0.6, 1.0, 0.2, 0.3, 0.5])
    grads = np.arange(12.0).reshape(6, 2)
    return BasisFunctions(indptr, indices, values, grads, None, np.array([False, True, False]))


def test_take_rows_by_index_and_mask():
    b = _basis()
    s = b.take([2, 0])
    assert s.indptr.tolist() == [0, 3, 5]
    assert s.values.tolist() == [0.2, 0.3, 0.5, 0.4, 0.6]
    assert np.array_equal(s.gradients, b.gradients[[3, 4, 5, 0, 1]])
    assert s.outside.tolist() == [False, False]
    m = b.take(np.array([False, True, True]))
    assert m.indices.tolist() == [2, 0, 1, 2]
    assert np.allclose(m.to_csr(3).toarray(), b.to_csr(3).toarray()[1:])


def test_renumbered_maps_local_to_global():
    b = _basis().renumbered([7, 3, 9])
    assert b.indices.tolist() == [7, 3, 9, 7, 3, 9]
    assert b.to_csr(10)[0, 3] == 0.6
