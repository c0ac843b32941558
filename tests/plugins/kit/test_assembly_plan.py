import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse import csr_matrix

from pointatlas_kit.assembly_plan import make_plan, node_sparsity_pattern
from pointatlas_kit.atlas_quadrature import AtlasQuadrature
from pointatlas_physics.kirchhoff_love.nonlinear import tangent_stiffness


def test_pattern_equals_incidence_product(cylinder_patch):
    q, _ = cylinder_patch
    row_ptr, cols = node_sparsity_pattern(q.indptr, q.indices, q.n_nodes)
    B = csr_matrix((np.ones(len(q.indices)), q.indices, q.indptr), (q.n_points, q.n_nodes))
    S = (B.T @ B).tocsr()
    S.sort_indices()
    assert np.array_equal(row_ptr, S.indptr) and np.array_equal(cols, S.indices)


def test_small_blocks_give_same_matrix(cylinder_patch, material):
    """Cutting the points into many tiny blocks (cap) must not change the assembled matrix."""
    q, P = cylinder_patch
    U = 0.03 * np.random.default_rng(0).standard_normal((q.n_nodes, 3))
    K = tangent_stiffness(q, material, U)
    q2 = AtlasQuadrature(indptr=q.indptr, indices=q.indices, basis=q.basis, weights=q.weights,
                         chart=np.arange(q.n_points) % 5, positions=q.positions,
                         tangents=q.tangents, second=q.second, orientation=q.orientation,
                         n_nodes=q.n_nodes)
    q2._plan = make_plan(q2.indptr, q2.indices, q2.basis, q2.chart, q2.n_nodes, cap=1)
    assert len(q2._plan.block_ptr) - 1 > len(q.assembly_plan().block_ptr) - 1
    K2 = tangent_stiffness(q2, material, U)
    assert abs(K - K2).max() < 1e-12 * abs(K).max()


@settings(max_examples=40, deadline=None)
@given(n_nodes=st.integers(1, 150), n_points=st.integers(0, 120),
       support=st.integers(1, 70), seed=st.integers(0, 2**32 - 1), shuffle=st.booleans())
def test_batched_pattern_equals_incidence_product_for_any_supports_and_order(
        n_nodes, n_points, support, seed, shuffle):
    """The bit-set pattern (batches of points, unions over 64-bit words) is exactly BᵀB for
    supports of any size, overlap and order, including nodes no point touches."""
    rng = np.random.default_rng(seed)
    sizes = rng.integers(1, min(support, n_nodes) + 1, n_points)
    indptr = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    indices = np.concatenate([rng.choice(n_nodes, k, replace=False) for k in sizes]
                             ).astype(np.int64) if n_points else np.empty(0, np.int64)
    order = rng.permutation(n_points) if shuffle else None
    row_ptr, cols = node_sparsity_pattern(indptr, indices, n_nodes, order)
    B = csr_matrix((np.ones(len(indices)), indices, indptr), (n_points, n_nodes))
    S = (B.T @ B).tocsr()
    S.sort_indices()
    assert np.array_equal(row_ptr, S.indptr) and np.array_equal(cols, S.indices)
