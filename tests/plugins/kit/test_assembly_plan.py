import numpy as np
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
