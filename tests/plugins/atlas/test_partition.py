"""The grouping of labels behind every per-patch loop: the same sets, in the same order, as
the per-label scan ``np.flatnonzero(labels == k)`` it replaces."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from pointatlas_atlas.partition import label_groups, label_members, split_disconnected


@settings(max_examples=60, deadline=None)
@given(arrays(np.int64, st.integers(0, 300), elements=st.integers(-3, 40)))
def test_label_groups_equal_the_per_label_scan(labels):
    groups = list(label_groups(labels))
    assert [k for k, _ in groups] == np.unique(labels).tolist()
    for k, idx in groups:
        np.testing.assert_array_equal(idx, np.flatnonzero(labels == k))
    wanted = [5, -3, 41, 0, 5]
    for k, idx in zip(wanted, label_members(labels, wanted)):
        np.testing.assert_array_equal(idx, np.flatnonzero(labels == k))


def test_split_disconnected_makes_components_parts():
    from scipy.sparse import csr_matrix

    # a path 0-1-2 and a path 3-4, all labelled 0, and node 5 labelled 1
    rows, cols = [0, 1, 1, 2, 3, 4], [1, 0, 2, 1, 4, 3]
    A = csr_matrix((np.ones(6), (rows, cols)), shape=(6, 6))
    out = split_disconnected(A, np.array([0, 0, 0, 0, 0, 1]))
    assert out.tolist() == [0, 0, 0, 1, 1, 2]


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_patch_share_is_the_column_sum_bit_for_bit(seed):
    """ψ_κ from the members' columns only equals weights[:, members].sum(axis=1) exactly
    (same order of addition), also where the patch does not reach (0)."""
    import scipy.sparse as sp

    from pointatlas_atlas.partition import patch_share, share_at

    rng = np.random.default_rng(seed)
    N, M = int(rng.integers(1, 300)), int(rng.integers(1, 50))
    W = sp.random(N, M, density=rng.uniform(0.0, 0.4), random_state=seed, format="csr")
    W.data = rng.random(W.nnz) * 10.0 ** rng.uniform(-8, 2, W.nnz)
    W = W.tocsc()
    members = rng.choice(M, size=int(rng.integers(1, M + 1)), replace=False)
    expected = np.asarray(W[:, members].sum(axis=1)).ravel()
    rows, psi = patch_share(W, members)
    full = np.zeros(N)
    full[rows] = psi
    np.testing.assert_array_equal(full, expected)
    at = np.unique(rng.integers(0, N, 25))
    np.testing.assert_array_equal(share_at(rows, psi, at), expected[at])


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_subgraph_is_scipys_row_and_column_selection(seed):
    """The induced subgraph built from the selected rows only equals scipy's
    adjacency[idx][:, idx] (structure and values), for any order of idx."""
    import scipy.sparse as sp

    from pointatlas_atlas.partition import subgraph

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 200))
    A = sp.random(n, n, density=rng.uniform(0.0, 0.2), random_state=seed, format="csr")
    A = (A + A.T).tocsr()
    idx = rng.permutation(n)[:int(rng.integers(0, n + 1))]
    expected = A[idx][:, idx].tocsr()
    expected.sort_indices()
    got = subgraph(A, idx)
    assert got.shape == expected.shape
    np.testing.assert_array_equal(got.indptr, expected.indptr)
    np.testing.assert_array_equal(got.indices, expected.indices)
    np.testing.assert_array_equal(got.data, expected.data)
