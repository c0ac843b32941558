"""Atlas quadrature that knows no physics: points, weights, basis jets and surface geometry.

Each chart κ integrates with Gauss points ξ_g on the Delaunay triangles of its embedded
nodes, weighted by the partition of unity (thesis Eq. 14, Paper 2 §3.3):

    ∫_Γ f dΓ ≈ Σ_κ Σ_g w_g J_κ(ξ_g) ψ_κ(φ_κ(ξ_g)) f(φ_κ(ξ_g)).

At every point the kit keeps the basis functions that do not vanish there with their chart
derivatives up to the order the fields ask for (columns :data:`.fields.BASIS_COLUMNS`,
CSR layout over global node ids), and the reference geometry of the chart there: position
X, tangents X_,α, second derivatives X_,αβ (order 2), the metric a_αβ = X_,α·X_,β and the
unit normal N of the atlas's one orientation (:mod:`pointatlas_atlas.orientation`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit

from pointatlas.errors import InputError

from .fields import COLUMNS_FOR_ORDER


@dataclass
class AtlasQuadrature:
    """Quadrature points of an atlas with their basis jets and reference geometry.

    indptr (m+1,), indices (nnz,): the nodes of point q are indices[indptr[q]:indptr[q+1]]
    basis (nnz, n_columns): p_a and its chart derivatives (chart length units^-k)
    weights (m,): w_g J ψ (length²);  chart (m,): chart id of each point
    positions (m, 3), tangents (m, 2, 3), second (m, 2, 2, 3) or None (order < 2)
    orientation (m,): ±1, the sign that turns X_,1 × X_,2 into the atlas's normal
    n_nodes: number of atlas nodes (control points, ghosts included)
    """

    indptr: np.ndarray
    indices: np.ndarray
    basis: np.ndarray
    weights: np.ndarray
    chart: np.ndarray
    positions: np.ndarray
    tangents: np.ndarray
    second: np.ndarray | None
    orientation: np.ndarray
    n_nodes: int
    _plan: object = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        c = np.ascontiguousarray
        self.indptr = c(self.indptr, dtype=np.int64)
        self.indices = c(self.indices, dtype=np.int64)
        self.basis = c(self.basis, dtype=np.float64)
        self.weights = c(self.weights, dtype=np.float64)
        self.chart = c(self.chart, dtype=np.int64)
        self.n_nodes = int(self.n_nodes)
        m, nnz = len(self.indptr) - 1, len(self.indices)
        if self.indptr[0] != 0 or self.indptr[-1] != nnz or np.any(np.diff(self.indptr) < 0):
            raise InputError(f"AtlasQuadrature.indptr must start at 0, be non-decreasing and "
                             f"end at len(indices) = {nnz}.")
        for name, got, want in (("basis", self.basis.shape[0], nnz),
                                ("weights", len(self.weights), m),
                                ("chart", len(self.chart), m),
                                ("positions", len(self.positions), m),
                                ("tangents", len(self.tangents), m)):
            if got != want:
                raise InputError(f"AtlasQuadrature.{name} has {got} rows; expected {want}.")
        if nnz and (self.indices.min() < 0 or self.indices.max() >= self.n_nodes):
            raise InputError(f"AtlasQuadrature.indices must lie in [0, {self.n_nodes}).")

    @property
    def n_points(self) -> int:
        return len(self.indptr) - 1

    @property
    def order(self) -> int:
        """The highest chart derivative order the basis holds (0, 1 or 2)."""
        return {1: 0, 3: 1, 6: 2}[self.basis.shape[1]]

    @property
    def metric(self) -> np.ndarray:
        """(m, 2, 2) a_αβ = X_,α · X_,β (length² per chart length²)."""
        T = self.tangents
        return np.einsum("mai,mbi->mab", T, T)

    @property
    def inverse_metric(self) -> np.ndarray:
        """(m, 2, 2) a^αβ."""
        return np.linalg.inv(self.metric)

    @property
    def normals(self) -> np.ndarray:
        """(m, 3) unit normals of the atlas's one orientation."""
        n = np.cross(self.tangents[:, 0], self.tangents[:, 1])
        n /= np.linalg.norm(n, axis=1)[:, None]
        return n * self.orientation[:, None]

    def reference_jet(self) -> np.ndarray:
        """(m, 5, 3) Y = (X_,1, X_,2, X_,11, X_,12, X_,22) (order 2 only)."""
        if self.second is None:
            raise InputError("the reference second derivatives were not kept: build the "
                             "quadrature with order=2.")
        S = self.second
        return np.ascontiguousarray(np.stack(
            [self.tangents[:, 0], self.tangents[:, 1], S[:, 0, 0],
             0.5 * (S[:, 0, 1] + S[:, 1, 0]), S[:, 1, 1]], axis=1))

    def interpolation(self):
        """scipy CSR (m, n_nodes) of p_a at the points: nodal values -> point values."""
        from scipy.sparse import csr_matrix

        return csr_matrix((self.basis[:, 0], self.indices, self.indptr),
                          shape=(self.n_points, self.n_nodes))

    def integrate(self, values) -> float:
        """Σ_q w_q f_q for point values f (m,) (∫_Γ f dΓ)."""
        return float(self.weights @ np.asarray(values, dtype=np.float64))

    def assembly_plan(self):
        """Cached :class:`.assembly_plan.AssemblyPlan` (pattern, point blocks)."""
        if self._plan is None:
            from .assembly_plan import make_plan

            self._plan = make_plan(self.indptr, self.indices, self.basis, self.chart,
                                   self.n_nodes)
        return self._plan


@njit(cache=True, nogil=True)
def _pack_jets(values, gradients, hessians, out):
    """out[t] = (p, p_,1, p_,2, p_,11, ½(p_,12 + p_,21), p_,22)[:out.shape[1]] row by row (one
    pass over the rows of ``out`` instead of one strided pass per column)."""
    ncol = out.shape[1]
    for t in range(out.shape[0]):
        out[t, 0] = values[t]
        if ncol > 1:
            out[t, 1] = gradients[t, 0]
            out[t, 2] = gradients[t, 1]
        if ncol > 3:
            out[t, 3] = hessians[t, 0, 0]
            out[t, 4] = 0.5 * (hessians[t, 0, 1] + hessians[t, 1, 0])
            out[t, 5] = hessians[t, 1, 1]


def atlas_quadrature(atlas, order: int, release_basis: bool = False) -> AtlasQuadrature:
    """The :class:`AtlasQuadrature` of a built atlas (``build_quadrature(keep_basis=True)``),
    with basis columns up to chart derivative ``order``.

    The arrays are allocated once and filled chart by chart (no concatenated temporaries).
    With ``release_basis`` each chart's own copy of the basis is dropped once it is copied
    (``atlas.quadrature_[k].basis = None``): the kit's quadrature then holds the only copy,
    which halves the memory of a physics model (the basis is most of it; measured on the
    4 000-point hemisphere shell: 3.77 GB peak before)."""
    q = getattr(atlas, "quadrature_", None)
    if not q or any(c.basis is None for c in q if len(c.weights)):
        raise InputError("the atlas quadrature has no basis: build it with "
                         "atlas.build_quadrature(keep_basis=True) (a physics model releases "
                         "the atlas's copy: use its quadrature).")
    parts = [(k, c) for k, c in enumerate(q) if len(c.weights)]
    signs = np.asarray(getattr(atlas, "chart_orientation_", np.ones(len(q))), float)
    return pack_quadrature(parts, signs, atlas.points_.shape[0], order, release_basis)


def pack_quadrature(parts, signs, n_nodes: int, order: int,
                    release_basis: bool = False) -> AtlasQuadrature:
    """The :class:`AtlasQuadrature` of the charts ``parts`` = [(chart id k, its
    ChartQuadrature with ``basis`` in global node ids)], ``signs`` (L,) the charts'
    orientations, basis columns up to chart derivative ``order``; ``release_basis`` drops
    each chart's basis once copied (see :func:`atlas_quadrature`)."""
    ncol = COLUMNS_FOR_ORDER[order]
    if order >= 2 and any(c.second is None or c.basis.hessians is None for _, c in parts):
        raise InputError("order-2 fields need the charts' second derivatives: build the "
                         "quadrature with need_second=True.")
    m = sum(len(c.weights) for _, c in parts)
    nnz = sum(len(c.basis.indices) for _, c in parts)
    indptr = np.zeros(m + 1, np.int64)
    indices = np.empty(nnz, np.int64)
    basis = np.empty((nnz, ncol))
    weights, chart = np.empty(m), np.empty(m, np.int64)
    positions, tangents = np.empty((m, 3)), np.empty((m, 2, 3))
    second = np.empty((m, 2, 2, 3)) if order >= 2 else None
    p0 = z0 = 0
    for k, c in parts:
        b = c.basis
        p1, z1 = p0 + len(c.weights), z0 + len(b.indices)
        indptr[p0 + 1:p1 + 1] = np.asarray(b.indptr[1:], np.int64) + z0
        indices[z0:z1] = b.indices
        _pack_jets(b.values, b.gradients if order >= 1 else np.zeros((0, 2)),
                   b.hessians if order >= 2 else np.zeros((0, 2, 2)), basis[z0:z1])
        if order >= 2:
            second[p0:p1] = c.second
        weights[p0:p1], chart[p0:p1] = c.weights, k
        positions[p0:p1], tangents[p0:p1] = c.positions, c.tangents
        if release_basis:
            c.basis = None
        p0, z0 = p1, z1
    return AtlasQuadrature(
        indptr=indptr, indices=indices, basis=basis, weights=weights, chart=chart,
        positions=positions, tangents=tangents, second=second,
        orientation=np.asarray(signs, float)[chart], n_nodes=n_nodes)


def node_quadrature(atlas, nodes, order: int) -> tuple[AtlasQuadrature, np.ndarray]:
    """(AtlasQuadrature at control points ``nodes`` with unit weights, rows): each node in
    its best chart (largest ψ_κ, :func:`pointatlas_atlas.evaluation.node_charts`) at its own
    embedded coordinates ξ_a = Ξ_κ[a], with that chart's reference geometry (thesis Eq. 2).
    ``rows`` (k,) indexes ``nodes`` for each point; nodes where the chart's basis is
    undefined (flagged outside, normally none) are left out."""
    from pointatlas_atlas.chart import chart_derivatives
    from pointatlas_atlas.evaluation import node_charts
    from pointatlas_atlas.partition import label_groups

    nodes = np.asarray(nodes, np.int64)
    chart, local = node_charts(atlas, nodes)
    ncol = COLUMNS_FOR_ORDER[order]
    signs = np.asarray(getattr(atlas, "chart_orientation_", np.ones(len(atlas.charts_))), float)
    parts, rows = [], []
    for k, sel in label_groups(chart):
        c = atlas.charts_[k]
        b = c.approximant.evaluate(c.xi_nodes[local[sel]], order=max(order, 1))
        if b.outside is not None and b.outside.any():
            keep = np.flatnonzero(~b.outside)
            b, sel = b.take(keep), sel[keep]
        if len(sel) == 0:
            continue
        X, T, S = chart_derivatives(b, c.control_points, max(order, 1))
        cols = [b.values, b.gradients[:, 0], b.gradients[:, 1]]
        if order >= 2:
            H = b.hessians
            cols += [H[:, 0, 0], 0.5 * (H[:, 0, 1] + H[:, 1, 0]), H[:, 1, 1]]
        parts.append((np.asarray(b.indptr, np.int64),
                      np.asarray(c.node_index, np.int64)[b.indices],
                      np.column_stack(cols)[:, :ncol], X, T, S, np.full(len(sel), k)))
        rows.append(sel)
    if not parts:
        raise InputError("no requested point has a defined basis in its chart; the atlas "
                         "cannot evaluate fields there (check the LME settings).")
    offsets = np.cumsum([0] + [len(p[1]) for p in parts])
    indptr = np.concatenate([[0]] + [p[0][1:] + o for p, o in zip(parts, offsets[:-1])])
    chart_ids = np.concatenate([p[6] for p in parts])
    q = AtlasQuadrature(
        indptr=indptr, indices=np.concatenate([p[1] for p in parts]),
        basis=np.concatenate([p[2] for p in parts]), weights=np.ones(len(chart_ids)),
        chart=chart_ids, positions=np.concatenate([p[3] for p in parts]),
        tangents=np.concatenate([p[4] for p in parts]),
        second=np.concatenate([p[5] for p in parts]) if order >= 2 else None,
        orientation=signs[chart_ids], n_nodes=atlas.points_.shape[0])
    return q, np.concatenate(rows)
