"""The PARDISO upper triangle and symmetry measure against scipy's own triu and A − Aᵀ."""
import numpy as np
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from pointatlas_solvers.symmetric_upper import symmetric_upper


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 40), density=st.floats(0.0, 0.6), seed=st.integers(0, 2**32 - 1),
       symmetric=st.booleans(), duplicates=st.booleans())
def test_upper_and_asymmetry_equal_scipy(n, density, seed, symmetric, duplicates):
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=density, random_state=rng, format="coo")
    if symmetric:
        A = (A + A.T).tocoo()
    if duplicates and A.nnz:   # unsummed duplicates and unsorted rows, as a COO import gives
        A = sp.csr_matrix((np.r_[A.data, A.data], (np.r_[A.row, A.row], np.r_[A.col, A.col])),
                          shape=A.shape)
        A.has_canonical_format = False
    D = sp.csr_matrix(A).toarray()
    asym, U = symmetric_upper(A)
    assert asym == np.abs(D - D.T).max()
    assert U.has_sorted_indices
    assert np.array_equal(U.toarray(), np.triu(D))
    assert np.all(U.diagonal() == np.diag(D)) and all(
        i in U.indices[U.indptr[i]:U.indptr[i + 1]] for i in range(n))   # diagonal stored
    rows = np.repeat(np.arange(n), np.diff(U.indptr))
    assert np.all(U.indices >= rows)


def test_explicit_zeros_and_the_input_are_kept():
    A = sp.csr_matrix((np.array([0.0, 2.0, 2.0]), np.array([1, 2, 0]), np.array([0, 2, 2, 3])),
                      shape=(3, 3))
    before = A.copy()
    asym, U = symmetric_upper(A)
    assert asym == 0.0
    assert U.nnz == 5   # zeros stored: a_00, a_01 (explicit), a_11, a_22; and a_02 = 2
    assert (A != before).nnz == 0 and np.array_equal(A.indices, before.indices)
