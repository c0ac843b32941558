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


@settings(max_examples=80, deadline=None)
@given(sizes=st.lists(st.integers(0, 5), min_size=1, max_size=60), data=st.data())
def test_compacted_gives_the_rows_of_take_in_place(sizes, data):
    """compacted (increasing rows, kept in place) equals take on a fresh copy: runs moved to
    the front of the same arrays, scattered rows taken; non-increasing rows refused."""
    import pytest

    m = len(sizes)
    indptr = np.concatenate([[0], np.cumsum(sizes)])
    nnz = int(indptr[-1])

    def fresh():
        return BasisFunctions(indptr.copy(), np.arange(nnz) % 7, np.arange(nnz) * 0.5,
                              np.arange(2.0 * nnz).reshape(nnz, 2),
                              np.arange(4.0 * nnz).reshape(nnz, 2, 2), np.arange(m) % 3 == 0)

    keep = np.array(data.draw(st.lists(st.booleans(), min_size=m, max_size=m)))
    if data.draw(st.booleans()):  # mostly one long run, as a chart's kept points are
        a = data.draw(st.integers(0, m - 1))
        keep[:] = False
        keep[a:data.draw(st.integers(a + 1, m))] = True
    rows = np.flatnonzero(keep)
    expected, b = fresh().take(rows), fresh()
    got = b.compacted(rows)
    for name in ("indptr", "indices", "values", "gradients", "hessians", "outside"):
        assert np.array_equal(getattr(got, name), getattr(expected, name)), name
    if len(rows) > 1:
        with pytest.raises(ValueError, match="strictly increasing"):
            fresh().compacted(rows[::-1])


def test_compacted_reuses_the_arrays_when_it_keeps_most_of_them():
    n = 60
    indptr = np.arange(0, 3 * n + 1, 3)
    b = BasisFunctions(indptr, np.arange(3 * n), np.arange(3.0 * n),
                       np.arange(6.0 * n).reshape(-1, 2))
    values = b.values
    got = b.compacted(np.r_[2:50, 53:60])
    assert np.shares_memory(got.values, values) and got.values.tolist() == \
        list(np.r_[6.0:150.0, 159.0:180.0])
    source = np.arange(3.0 * n)
    small = BasisFunctions(indptr, np.arange(3 * n), source).compacted(np.r_[0:20])
    assert not np.shares_memory(small.values, source)   # a third kept: copied, source freed
    assert small.values.tolist() == list(np.arange(60.0))
