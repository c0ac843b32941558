"""Essential boundary conditions as linear constraints C U = g on the nodal displacements.

Paper 1 App. D / thesis App. E.2: displacement and rotation conditions are imposed at
boundary points through Lagrange multipliers (here an augmented Lagrangian, see
:mod:`pointatlas_solvers.augmented_lagrangian`). At a point x on the surface,
u(x) = Σ_a p_a U_a and, for Kirchhoff–Love kinematics, the linearised change of the unit
normal is δn = −(n·u_,α) a^α (a^α the dual tangent basis), so:

* displacement rows  e·u(x) = Σ_a p_a e·U_a
* rotation rows      n·u_,α(x) = Σ_a p_a,α n·U_a        (clamped: δn = 0 ⇔ both vanish)
* symmetry rows      p·u_,e = Σ_α (a^α·e) p·u_,α = 0, p = n and e × n: the derivative across
                     the plane, φ_,e, stays parallel to e, so the normal stays in the plane
                     (exact at any rotation; the p = n row alone is the linearised δn·e = 0)

Rotation rows are scaled by the node spacing h so every row is a length (one penalty fits).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix

from pointatlas.errors import InputError

from pointatlas_kit.selectors import describe, select

RIGID_MOTIONS = ("translation along x", "translation along y", "translation along z",
                 "rotation about x", "rotation about y", "rotation about z")


@dataclass
class Constraints:
    """C (r, 3N) and g (r,) with the support each row comes from and the selected nodes."""

    matrix: csr_matrix
    rhs: np.ndarray
    row_support: np.ndarray          # (r,) index into the supports list
    nodes: list                      # per support: selected point indices


def _rows(basis, weights: np.ndarray, which: str, n_dof: int, alpha: int = 0):
    """COO pieces of rows Σ_a q_a (w·U_a), q = p (which='value') or p_,α ('gradient')."""
    counts = np.diff(basis.indptr)
    r = np.repeat(np.arange(basis.n_points), counts)
    q = basis.values if which == "value" else basis.gradients[:, alpha]
    rows, cols, vals = [], [], []
    for j in range(3):
        rows.append(r)
        cols.append(3 * basis.indices + j)
        vals.append(q * weights[r, j])
    return np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)


def _block(pieces, n_rows: int, n_dof: int) -> csr_matrix:
    r = np.concatenate([p[0] for p in pieces])
    c = np.concatenate([p[1] for p in pieces])
    v = np.concatenate([p[2] for p in pieces])
    return coo_matrix((v, (r, c)), shape=(n_rows, n_dof)).tocsr()


def _frames(atlas, chart: np.ndarray, xi: np.ndarray):
    """Tangents a_α (k, 2, 3), dual vectors a^α (k, 2, 3) and unit normals n (k, 3)."""
    from pointatlas_atlas import differential_geometry as dg

    T = np.empty((len(chart), 2, 3))
    for k in np.unique(chart):
        sel = np.flatnonzero(chart == k)
        _, T[sel], _, _ = atlas.charts_[k].evaluate(xi[sel], order=1)
    A = dg.metric(T)
    dual = np.einsum("kab,kbi->kai", np.linalg.inv(A), T)
    return T, dual, dg.unit_normal(T)


def support_constraints(atlas, points: np.ndarray, boundary: np.ndarray, curves: list,
                        supports: list, spacing: float, segment_points: int = 4
                        ) -> Constraints:
    """Assemble C U = g for all supports; ``points`` are the real (non-ghost) points, which
    are the first rows of the atlas's control points.

    Each constraint c(x) = 0 is imposed weakly with one multiplier per selected boundary node
    (Paper 1 App. D): row_i = ∫ N_i c ds / ∫ N_i ds with N_i the hat function of node i along
    the boundary curve, integrated with ``segment_points`` Gauss points per boundary segment
    (thesis: four per boundary cell). A node with no selected neighbour along a curve (e.g. a
    single held point) is collocated. ``segment_points = 0`` collocates at every node.
    """
    from pointatlas_atlas.evaluation import basis_at

    n_dof = 3 * atlas.points_.shape[0]
    blocks, rhs, owner, chosen = [], [], [], []
    for s_i, sup in enumerate(supports):
        nodes = select(sup.where, points, boundary, curves)
        chosen.append(nodes)
        chart, xi, A = boundary_quadrature(atlas, points, nodes, curves, spacing,
                                           segment_points)
        basis = basis_at(atlas, chart, xi, order=1)
        T, dual, n = _frames(atlas, chart, xi)
        k = len(chart)
        rows, values = [], []

        def add(weights, which="value", alpha=(0,), value=0.0):
            """Weak rows A·[Σ_α Σ_a q_a (w_α·U_a)] at the boundary quadrature points."""
            pieces = [_rows(basis, w, which, n_dof, a)
                      for a, w in zip(alpha, weights if which == "gradient" else [weights])]
            rows.append(A @ _block(pieces, k, n_dof))
            values.append(np.full(A.shape[0], float(value)))

        eye = np.eye(3)
        if sup.kind in ("clamped", "simply_supported"):
            for j in range(3):
                add(np.tile(eye[j], (k, 1)))
        if sup.kind == "clamped":  # n·u_,α = 0, α = 1, 2 (δn = 0)
            for a in range(2):
                scale = spacing / np.linalg.norm(T[:, a], axis=1)
                add([n * scale[:, None]], "gradient", (a,))
        if sup.kind == "symmetry":
            e = _unit(sup.normal)
            add(np.tile(e, (k, 1)))
            c = dual @ e  # u_,e = Σ_α c_α u_,α; rows p·u_,e = 0, p = n, e × n (module doc)
            across = np.cross(e, n)
            sine = np.linalg.norm(across, axis=1)
            if sine.min() < 0.5:
                raise InputError(
                    f"support {s_i} (symmetry, normal {list(sup.normal)}): the plane does not "
                    "cut the surface at right angles at some selected points (the surface "
                    "normal there is within 30° of the plane's normal). Give the normal of the "
                    "symmetry plane itself, and select only points on that plane.")
            for p in (n, across / sine[:, None]):
                add([p * (spacing * c[:, a])[:, None] for a in range(2)], "gradient", (0, 1))
        if sup.kind == "diaphragm":
            e = _unit(sup.normal)
            t1 = np.cross(e, eye[np.argmin(np.abs(e))])
            t1 /= np.linalg.norm(t1)
            for t in (t1, np.cross(e, t1)):
                add(np.tile(t, (k, 1)))
        if sup.kind in ("fixed", "displacement"):
            comps = sup.components if sup.components else [0, 1, 2]
            for j in comps:
                add(np.tile(eye[j], (k, 1)),
                    value=0.0 if sup.kind == "fixed" else float(sup.value[j]))
        from scipy.sparse import vstack

        block = vstack(rows).tocsr()
        blocks.append(block)
        rhs.append(np.concatenate(values))
        owner.append(np.full(block.shape[0], s_i))
    from scipy.sparse import vstack

    return Constraints(vstack(blocks).tocsr(), np.concatenate(rhs), np.concatenate(owner),
                       chosen)


def boundary_quadrature(atlas, points, nodes, curves, spacing: float, n_gauss: int = 4):
    """(chart, ξ, A): evaluation points on the selected boundary and the (k_nodes, n_eval)
    matrix A of hat-function weights, rows normalised to sum 1.

    The points are the nodes themselves (used by collocated nodes) and ``n_gauss``
    Gauss–Legendre points on every segment joining two selected neighbours along a curve;
    a segment point is the chart-space interpolation ξ = (1 − t) ξ_a + t ξ_b in the chart
    of node a, with weight w_g ℓ_ab N(t) towards each end node.
    """
    from scipy.sparse import coo_matrix as coo

    from pointatlas_atlas.evaluation import node_charts

    chart, local = node_charts(atlas, nodes)
    xi = [atlas.charts_[c].xi_nodes[j] for c, j in zip(chart, local)]
    charts = list(chart)
    picked = np.zeros(points.shape[0], bool)
    picked[nodes] = True
    where = {int(a): i for i, a in enumerate(nodes)}
    if n_gauss > 0:
        tg, wg = np.polynomial.legendre.leggauss(n_gauss)
        tg, wg = 0.5 * (tg + 1.0), 0.5 * wg
    rows, cols, vals = [], [], []
    covered = np.zeros(len(nodes), bool)
    from pointatlas_atlas.boundary import curve_segments

    for a, b in curve_segments(points, curves, 2.0 * spacing) if n_gauss > 0 else []:
        ell = np.linalg.norm(points[a] - points[b])
        if picked[a] and picked[b]:  # a segment of the selected boundary
            ia, ib = where[int(a)], where[int(b)]
            k = charts[ia]
            jb = np.flatnonzero(atlas.charts_[k].node_index == b)
            if jb.size == 0:
                continue
            xa, xb = xi[ia], atlas.charts_[k].xi_nodes[jb[0]]
            for t, w in zip(tg, wg):
                e = len(charts)
                xi.append((1 - t) * xa + t * xb)
                charts.append(k)
                rows += [ia, ib]
                cols += [e, e]
                vals += [w * ell * (1 - t), w * ell * t]
            covered[[ia, ib]] = True
    lone = np.flatnonzero(~covered)
    rows += lone.tolist()
    cols += lone.tolist()
    vals += [1.0] * lone.size
    A = coo((vals, (rows, cols)), shape=(len(nodes), len(charts))).tocsr()
    A = (coo((1.0 / np.asarray(A.sum(axis=1)).ravel(), (np.arange(len(nodes)),) * 2),
             shape=(len(nodes),) * 2) @ A).tocsr()
    return (np.asarray(charts, dtype=np.int64), np.asarray(xi).reshape(len(charts), -1), A)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    norm = np.linalg.norm(v)
    if not norm > 0:
        raise InputError(f"normal {list(v)} has zero length; give the plane's normal vector.")
    return v / norm


def rigid_motions(nodes: np.ndarray) -> np.ndarray:
    """(3N, 6) nodal displacements of the six rigid motions (translations, ω × P_a)."""
    N = nodes.shape[0]
    R = np.zeros((3 * N, 6))
    for j in range(3):
        R[j::3, j] = 1.0
        w = np.eye(3)[j]
        R[:, 3 + j] = np.cross(w, nodes).ravel()
    return R


def check_rigid_motions(C: csr_matrix, nodes: np.ndarray, supports: list, tol: float = 1e-8):
    """Raise :class:`InputError` if a rigid motion satisfies every constraint (singular
    problem), naming the free motions and the fix."""
    R = rigid_motions(nodes)
    R /= np.linalg.norm(R, axis=0)
    CR = C @ R
    w, V = np.linalg.eigh(CR.T @ CR)
    free = w < tol * max(w.max(), 1e-300)
    if free.any() or C.shape[0] == 0:
        names = [RIGID_MOTIONS[int(np.argmax(np.abs(V[:, i])))] for i in np.flatnonzero(free)]
        held = "; ".join(describe(s.where) + f" ({s.kind})" for s in supports) or "nothing"
        raise InputError(
            f"the shell is not held against {len(names)} rigid motion(s) "
            f"(mostly: {', '.join(names)}): its stiffness is singular. Supports given: {held}. "
            "Add a support that prevents them, e.g. {kind: fixed, components: [2], where: "
            "{expression: '...', on_boundary: false}} at one point.")
