"""The upper triangle of a symmetric sparse matrix for PARDISO, with its symmetry checked.

PARDISO's symmetric formats (mtype 2, −2) read the upper triangle in CSR with every diagonal
entry stored. One pass over the sorted CSR rows gives both that triangle and max |A − Aᵀ|
(each stored upper a_ij against a_ji, found by a cursor that walks each row's lower
entries once; a missing mirror counts as 0), instead of
forming A − Aᵀ and triu(A) as scipy matrices (1.0 s → about 0.1 s on the 10⁷-entry
hemisphere shell matrix).
"""
from __future__ import annotations

import numpy as np
from numba import njit
from scipy.sparse import csr_matrix


@njit(cache=True, nogil=True)
def _asymmetry(indptr, indices, data):
    """max |a_ij − a_ji| over the stored entries (a missing mirror is 0), in one pass.

    Rows i are visited in order; each row j keeps a cursor on its lower entries (columns
    < j, sorted). An upper entry a_ij moves row j's cursor up to column i: a lower entry it
    passes has no stored mirror (its column's row came earlier and did not stop there),
    and the one at column i, if any, is a_ji. The lower entries left behind the cursors at
    the end have no mirror either. Each entry is touched once (the former bisection in
    row j for every upper entry: 0.084 s against 0.039 s on the 4.5·10⁶-entry
    pull-out tangent)."""
    n = len(indptr) - 1
    cursor = np.empty(n, np.int64)
    for j in range(n):
        cursor[j] = indptr[j]
    asym = 0.0
    for i in range(n):
        for t in range(indptr[i], indptr[i + 1]):
            j = indices[t]
            if j <= i:
                continue
            c = cursor[j]
            end = indptr[j + 1]
            while c < end and indices[c] < i:   # lower entries of row j without a mirror
                asym = max(asym, abs(data[c]))
                c += 1
            w = 0.0
            if c < end and indices[c] == i:
                w = data[c]
                c += 1
            cursor[j] = c
            asym = max(asym, abs(data[t] - w))
    for j in range(n):   # the lower entries no upper entry reached
        c = cursor[j]
        while c < indptr[j + 1] and indices[c] < j:
            asym = max(asym, abs(data[c]))
            c += 1
    return asym


@njit(cache=True, nogil=True)
def _upper_kernel(indptr, indices, data, count_only, up_ptr, up_idx, up_val):
    """Count (up_ptr[i+1]) or fill the upper triangle with the diagonal (canonical CSR)."""
    n = len(indptr) - 1
    for i in range(n):
        k = 0 if count_only else up_ptr[i]
        diag = False
        for t in range(indptr[i], indptr[i + 1]):
            j = indices[t]
            if j < i:
                continue
            if j > i and not diag:     # no stored diagonal: an explicit zero before a_ij
                if not count_only:
                    up_idx[k] = i
                    up_val[k] = 0.0
                k += 1
                diag = True
            if j == i:
                diag = True
            if not count_only:
                up_idx[k] = j
                up_val[k] = data[t]
            k += 1
        if not diag:
            if not count_only:
                up_idx[k] = i
                up_val[k] = 0.0
            k += 1
        if count_only:
            up_ptr[i + 1] = k


def symmetric_upper(A) -> tuple[float, csr_matrix]:
    """(max |A − Aᵀ|, upper triangle of A as CSR with sorted indices and every diagonal entry
    stored, explicit zeros where A has none). A is not modified."""
    A = csr_matrix(A, dtype=float)
    if A.shape[0] != A.shape[1]:
        raise ValueError(f"a square matrix is needed, got {A.shape}")
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()   # sorts the indices too
    indptr, indices = A.indptr.astype(np.int64), A.indices.astype(np.int64)
    n = A.shape[0]
    up_ptr = np.zeros(n + 1, np.int64)
    empty_i, empty_v = np.empty(0, np.int64), np.empty(0)
    asym = _asymmetry(indptr, indices, A.data)
    _upper_kernel(indptr, indices, A.data, True, up_ptr, empty_i, empty_v)
    up_ptr = np.cumsum(up_ptr)
    up_idx = np.empty(up_ptr[-1], np.int64)
    up_val = np.empty(up_ptr[-1])
    _upper_kernel(indptr, indices, A.data, False, up_ptr, up_idx, up_val)
    index = np.int32 if max(n, len(up_idx)) < 2**31 - 1 else np.int64
    return float(asym), csr_matrix((up_val, up_idx.astype(index), up_ptr.astype(index)),
                                   shape=A.shape)
