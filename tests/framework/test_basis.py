"""BasisFunctions row subsets and renumbering keep every row intact."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

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


@settings(max_examples=80, deadline=None)
@given(sizes=st.lists(st.integers(0, 5), min_size=1, max_size=60), data=st.data())
def test_take_equals_row_by_row_copy_for_runs_and_scattered_rows(sizes, data):
    """Long runs of consecutive rows (copied as slices) and scattered or repeated rows
    (gathered) both give exactly the rows asked for, in order."""
    m = len(sizes)
    indptr = np.concatenate([[0], np.cumsum(sizes)])
    nnz = int(indptr[-1])
    b = BasisFunctions(indptr, np.arange(nnz) % 7, np.arange(nnz) * 0.5,
                       np.arange(2.0 * nnz).reshape(nnz, 2),
                       np.arange(4.0 * nnz).reshape(nnz, 2, 2), np.arange(m) % 3 == 0)
    kind = data.draw(st.sampled_from(["runs", "any"]))
    if kind == "runs":
        keep = np.zeros(m, bool)
        a = data.draw(st.integers(0, m - 1))
        keep[a:data.draw(st.integers(a + 1, m))] = True
        rows = np.flatnonzero(keep)
    else:
        rows = np.array(data.draw(st.lists(st.integers(0, m - 1), max_size=40)), np.int64)
    s = b.take(rows)
    parts = [np.arange(indptr[r], indptr[r + 1]) for r in rows]
    flat = np.concatenate(parts) if parts else np.zeros(0, np.int64)
    assert np.array_equal(s.indptr, np.concatenate([[0], np.cumsum(np.diff(indptr)[rows])]))
    for name in ("indices", "values", "gradients", "hessians"):
        assert np.array_equal(getattr(s, name), getattr(b, name)[flat]), name
    assert np.array_equal(s.outside, b.outside[rows])
