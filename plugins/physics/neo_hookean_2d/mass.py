"""Mass of the body: lumped or consistent, with the clamped nodes held fixed.

For linear triangles of reference area A_e and density ρ (mass / length³, the plane-strain
body per unit thickness), the consistent mass matrix is M_ab = Σ_e ∫ ρ N_a N_b dA, element
matrix ρ A_e / 12 [[2, 1, 1], [1, 2, 1], [1, 1, 2]], and the lumped one its row sums,
m_a = Σ_{e ∋ a} ρ A_e / 3 (mass / length). The same scalar matrix acts on each component of
the (n, 2) positions, so M on the 2n DOFs is M ⊗ I₂ and T = ½ Σ_i v_iᵀ M v_i with v_i the
i-th component of the nodal velocities.
"""
from __future__ import annotations

import numpy as np

KINDS = ("lumped", "consistent")


def lumped_masses(triangles: np.ndarray, area: np.ndarray, density: float,
                  n_nodes: int) -> np.ndarray:
    """Nodal masses m_a = Σ_{e ∋ a} ρ A_e / 3 (n,), mass / length."""
    return np.bincount(triangles.ravel(), weights=np.repeat(density * area / 3.0, 3),
                       minlength=n_nodes)


def consistent_mass_matrix(triangles: np.ndarray, area: np.ndarray, density: float,
                           n_nodes: int):
    """M_ab = Σ_e ρ A_e (1 + δ_ab) / 12 over the triangles holding a and b (n × n CSR)."""
    from scipy.sparse import coo_matrix

    local = (np.ones((3, 3)) + np.eye(3)) / 12.0
    values = density * area[:, None, None] * local
    rows = np.repeat(triangles, 3, axis=1).ravel()
    cols = np.tile(triangles, (1, 3)).ravel()
    return coo_matrix((values.ravel(), (rows, cols)), shape=(n_nodes, n_nodes)).tocsr()


class Mass:
    """The mass matrix of one ``kind`` ('lumped' or 'consistent') restricted to the free
    nodes (``free``: boolean mask (n,)), factorised once for :meth:`accelerations`."""

    def __init__(self, kind: str, triangles, area, density: float, free: np.ndarray):
        n = len(free)
        self.kind, self.free = kind, np.asarray(free, bool)
        self.lumped = lumped_masses(triangles, area, density, n)
        if kind == "lumped":
            self.matrix = None
            self.inverse = np.where(self.free, 1.0 / self.lumped, 0.0)
        elif kind == "consistent":
            from scipy.sparse.linalg import splu

            self.matrix = consistent_mass_matrix(triangles, area, density, n)
            idx = np.flatnonzero(self.free)
            self._lu = splu(self.matrix[idx][:, idx].tocsc())
            self.inverse = None
        else:
            raise ValueError(f"mass kind {kind!r}: use one of {KINDS}")

    def apply(self, v: np.ndarray) -> np.ndarray:
        """M v for nodal vectors v (n, 2)."""
        if self.matrix is None:
            return self.lumped[:, None] * v
        return self.matrix @ v

    def kinetic_energy(self, v: np.ndarray) -> float:
        """T = ½ Σ_i v_iᵀ M v_i (energy per unit thickness)."""
        return 0.5 * float(np.sum(v * self.apply(v)))

    def accelerations(self, r: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """a = M_ff⁻¹ r_f on the free nodes, 0 on the clamped ones (r: force (n, 2))."""
        if out is None:
            out = np.empty_like(r)
        if self.matrix is None:
            np.multiply(self.inverse[:, None], r, out=out)
            return out
        out[:] = 0.0
        out[self.free] = self._lu.solve(np.ascontiguousarray(r[self.free]))
        return out

    def dof_matrix(self):
        """M ⊗ I₂ on the 2n DOFs (2a + i), as a sparse matrix (lumped: diagonal)."""
        from scipy.sparse import diags, identity, kron

        if self.matrix is None:
            return diags(np.repeat(self.lumped, 2)).tocsr()
        return kron(self.matrix, identity(2), format="csr")
