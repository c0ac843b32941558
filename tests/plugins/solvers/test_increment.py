"""One increment: Newton's line search on Π_ρ and the reactions of the supports."""
import numpy as np
import pytest
from scipy.sparse import csr_matrix

from pointatlas_solvers.increment import line_search, support_reactions


def test_line_search_backtracks_on_an_energy_increase():
    """A step that raises the out-of-balance force and the energy is shortened (Armijo)."""

    class Quartic:  # W = u⁴/4 on one free DOF: Newton from u = 1 overshoots nothing, but a
        C = np.zeros((0, 1))  # step of 3 (too long) raises W and |R|
        g = np.zeros(0)
        F = np.zeros(1)
        rho = 0.0

        def residual(self, U, mu, lam):
            return U**3, float(U[0] ** 4 / 4)

        def merit(self, W, U, mu, lam):
            return W

    eq = Quartic()
    eq.C = csr_matrix((0, 1))
    U, dU = np.array([1.0]), np.array([-3.0])
    R, W = eq.residual(U, None, 0)
    R_new, W_new = eq.residual(U + dU, None, 0)
    alpha, R_a, W_a = line_search(eq, U, np.zeros(0), np.zeros(0), 0.0, dU, R, W, R_new, W_new)
    assert alpha < 1 and W_a < W and R_a[0] == pytest.approx((1 - 3 * alpha) ** 3)


def test_reactions_are_the_resultants_of_each_supports_rows():
    """Two supports on 2 nodes × 2 components: support 0 holds node 0's x and y, support 1
    node 1's y twice (redundant rows); the reaction is −Σ Cᵀμ per support and component."""
    C = csr_matrix(np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 0, 1.0], [0, 0, 0, 2.0]]))
    mu = np.array([3.0, -1.0, 0.5, 0.25])
    out = support_reactions(C, mu, np.array([0, 0, 1, 1]), 2)
    np.testing.assert_array_equal(out, [[-3.0, 1.0], [0.0, -1.0]])
    assert support_reactions(csr_matrix((0, 4)), np.zeros(0), np.zeros(0, int), 2).shape == (0, 2)
