"""Quadrature data of a Kirchhoff–Love shell: basis derivatives and reference geometry per point.

The middle surface is X(ξ) = Σ_a p_a(ξ) P_a in each chart and the displacement
u(ξ) = Σ_a p_a(ξ) U_a uses the same basis (thesis §4.2, Paper 1 §3.1–3.2, Eq. 12). At every
quadrature point the shell kinematics need the chart derivatives

    y = (x_,1, x_,2, x_,11, x_,12, x_,22),  x_,α = X_,α + Σ_a p_a,α U_a,  x_,αβ likewise,

so a point stores p_a, p_a,1, p_a,2, p_a,11, p_a,12, p_a,22 of its support nodes (CSR), the
reference derivatives Y = (X_,1, X_,2, X_,11, X_,12, X_,22) and the weight

    w_q = (Gauss weight) × J_κ(ξ_q) × ψ_κ(φ_κ(ξ_q))   (reference area × partition of unity),

so that Σ_q w_q f(ξ_q) ≈ ∫_Ω f dΩ_0 (thesis Eq. 14, Paper 2 §3.3).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pointatlas.errors import InputError

BASIS_COLUMNS = ("p", "p_1", "p_2", "p_11", "p_12", "p_22")
"""Columns of ShellQuadrature.basis."""


@dataclass
class ShellQuadrature:
    """Quadrature points of a shell with the basis functions that do not vanish there.

    indptr : (m+1,) int64; the nodes of point q are indices[indptr[q]:indptr[q+1]]
    indices : (nnz,) int64 global node ids in [0, n_nodes)
    basis : (nnz, 6) float64, columns BASIS_COLUMNS (derivatives w.r.t. the chart ξ)
    reference : (m, 5, 3) float64, X_,1, X_,2, X_,11, X_,12, X_,22 (length / chart length^k)
    weights : (m,) float64, reference area × partition of unity per point (length²)
    group : (m,) int64 chart id of each point (points of a chart share a small node set)
    n_nodes : number of global nodes N (DOFs 3a + i)

    Arrays are treated as immutable: the assembly plan (sparsity pattern, point blocks) is
    cached on first use.
    """

    indptr: np.ndarray
    indices: np.ndarray
    basis: np.ndarray
    reference: np.ndarray
    weights: np.ndarray
    group: np.ndarray
    n_nodes: int
    _plan: object = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        self.indptr = np.ascontiguousarray(self.indptr, dtype=np.int64)
        self.indices = np.ascontiguousarray(self.indices, dtype=np.int64)
        self.basis = np.ascontiguousarray(self.basis, dtype=np.float64)
        self.reference = np.ascontiguousarray(self.reference, dtype=np.float64)
        self.weights = np.ascontiguousarray(self.weights, dtype=np.float64)
        self.group = np.ascontiguousarray(self.group, dtype=np.int64)
        self.n_nodes = int(self.n_nodes)
        self.validate()

    @property
    def n_points(self) -> int:
        return len(self.indptr) - 1

    @property
    def n_dofs(self) -> int:
        return 3 * self.n_nodes

    def validate(self) -> None:
        """Raise InputError if shapes or index ranges are inconsistent."""
        m = self.n_points
        nnz = len(self.indices)
        if m < 0 or self.indptr[0] != 0 or self.indptr[-1] != nnz or np.any(
                np.diff(self.indptr) < 0):
            raise InputError("ShellQuadrature.indptr must start at 0, be non-decreasing and end "
                             f"at len(indices) = {nnz}; got indptr[-1] = {self.indptr[-1]}.")
        checks = (("basis", self.basis.shape, (nnz, 6)),
                  ("reference", self.reference.shape, (m, 5, 3)),
                  ("weights", self.weights.shape, (m,)), ("group", self.group.shape, (m,)))
        for name, got, want in checks:
            if got != want:
                raise InputError(f"ShellQuadrature.{name} has shape {got}; expected {want} for "
                                 f"{m} points and {nnz} basis entries.")
        if nnz and (self.indices.min() < 0 or self.indices.max() >= self.n_nodes):
            raise InputError(f"ShellQuadrature.indices must lie in [0, n_nodes = {self.n_nodes});"
                             f" got range [{self.indices.min()}, {self.indices.max()}].")

    def check_displacements(self, U) -> np.ndarray:
        """U as a contiguous (n_nodes, 3) float64 array, or InputError."""
        U = np.ascontiguousarray(U, dtype=np.float64)
        if U.shape == (self.n_dofs,):
            U = U.reshape(self.n_nodes, 3)
        if U.shape != (self.n_nodes, 3):
            raise InputError(f"nodal displacements have shape {U.shape}; expected "
                             f"({self.n_nodes}, 3) or ({self.n_dofs},).")
        if not np.all(np.isfinite(U)):
            raise InputError("nodal displacements contain NaN or inf.")
        return U

    def assembly_plan(self):
        """Cached AssemblyPlan (node pattern, point order and blocks; see assembly_plan.py)."""
        if self._plan is None:
            from .assembly_plan import make_plan

            self._plan = make_plan(self.indptr, self.indices, self.basis, self.group,
                                   self.n_nodes)
        return self._plan

    def node_pattern(self) -> tuple[np.ndarray, np.ndarray]:
        """(row_ptr, cols) of the node-level stiffness pattern (a ~ b if they share a point)."""
        plan = self.assembly_plan()
        return plan.row_ptr, plan.cols


def from_basis(basis_functions, reference_tangents, reference_second, weights, group,
               n_nodes: int, node_index=None) -> ShellQuadrature:
    """ShellQuadrature from a pointatlas.basis.BasisFunctions evaluated with order=2.

    reference_tangents : (m, 2, 3) X_,α;  reference_second : (m, 2, 2, 3) X_,αβ
    weights : (m,) reference area × PU;  group : (m,) or a scalar chart id
    node_index : (n_local,) global ids of the basis' local node indices, or None (identity).
    """
    bf = basis_functions
    if bf.gradients is None or bf.hessians is None:
        raise InputError("the shell needs basis gradients and hessians: evaluate the "
                         "approximant with order=2.")
    m = bf.n_points
    idx = np.asarray(bf.indices, dtype=np.int64)
    if node_index is not None:
        idx = np.asarray(node_index, dtype=np.int64)[idx]
    basis = np.column_stack([bf.values, bf.gradients[:, 0], bf.gradients[:, 1],
                             bf.hessians[:, 0, 0], 0.5 * (bf.hessians[:, 0, 1]
                                                          + bf.hessians[:, 1, 0]),
                             bf.hessians[:, 1, 1]])
    T = np.asarray(reference_tangents, dtype=np.float64)
    S = np.asarray(reference_second, dtype=np.float64)
    if T.shape != (m, 2, 3) or S.shape != (m, 2, 2, 3):
        raise InputError(f"reference tangents/second derivatives have shapes {T.shape}, "
                         f"{S.shape}; expected ({m}, 2, 3) and ({m}, 2, 2, 3).")
    ref = np.stack([T[:, 0], T[:, 1], S[:, 0, 0], 0.5 * (S[:, 0, 1] + S[:, 1, 0]), S[:, 1, 1]],
                   axis=1)
    grp = np.broadcast_to(np.asarray(group, dtype=np.int64), (m,)).copy()
    return ShellQuadrature(np.asarray(bf.indptr, dtype=np.int64), idx, basis, ref,
                           np.asarray(weights, dtype=np.float64), grp, n_nodes)


def concatenate(parts: list[ShellQuadrature]) -> ShellQuadrature:
    """Stack the points of several ShellQuadrature objects on the same global node set."""
    if not parts:
        raise InputError("concatenate needs at least one ShellQuadrature.")
    n_nodes = parts[0].n_nodes
    if any(p.n_nodes != n_nodes for p in parts):
        raise InputError("all ShellQuadrature parts must have the same n_nodes; got "
                         f"{sorted({p.n_nodes for p in parts})}.")
    offsets = np.cumsum([0] + [len(p.indices) for p in parts])
    indptr = np.concatenate([[0]] + [p.indptr[1:] + o for p, o in zip(parts, offsets[:-1])])
    return ShellQuadrature(
        indptr, np.concatenate([p.indices for p in parts]),
        np.concatenate([p.basis for p in parts]), np.concatenate([p.reference for p in parts]),
        np.concatenate([p.weights for p in parts]), np.concatenate([p.group for p in parts]),
        n_nodes)
