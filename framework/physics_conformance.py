"""Conformance checks of a physics plugin's discrete energy on a small curved patch.

A physics written on the kit exposes ``discrete_energy(patch)``: its energies assembled on
the quadrature ``patch`` (a dict of arrays, built here without any plugin module:
LME basis from the registry on a jittered grid of a curved surface, Gauss points on its
Delaunay triangles, reference geometry X = Σ p_a P_a), returning an object with
``n_dofs``, ``energy(U) -> float``, ``residual(U) -> (Π, R)``, ``tangent(U) -> sparse``,
``frame_invariant`` and ``rigid_motion(R, t) -> U``. The checks (thesis Eq. 14–15):

* R = ∂Π/∂U and K = ∂R/∂U against central differences (the worst entry is named);
* K symmetric;
* where the energy claims frame invariance: Π = 0 and R = 0 for a finite rigid motion.
"""
from __future__ import annotations

import numpy as np

#: a three-point rule on the reference triangle (exact to degree 2): barycentric, weight
_TRIANGLE_RULE = (np.array([[2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]]),
                  np.full(3, 1 / 3))


def curved_points(n: int = 6, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(ξ (n², 2), P (n², 3)): a jittered n × n grid ξ of [0, 1]² (the edge points stay on the
    edges, the inner ones move by up to 0.15/n) lifted to the doubly curved open patch
    z = 0.3 x² − 0.2 xy + 0.25 y² (lengths in the units of the square's side)."""
    rng = np.random.default_rng(seed)
    g = np.linspace(0.0, 1.0, n)
    xi = np.array(np.meshgrid(g, g, indexing="ij")).reshape(2, -1).T
    inner = (xi > 0).all(axis=1) & (xi < 1).all(axis=1)
    xi[inner] += 0.15 / n * rng.uniform(-1, 1, (int(inner.sum()), 2))
    P = np.column_stack([xi, 0.3 * xi[:, 0] ** 2 - 0.2 * xi[:, 0] * xi[:, 1]
                         + 0.25 * xi[:, 1] ** 2])
    return xi, P


def curved_patch(n: int = 6, seed: int = 0) -> dict:
    """Quadrature arrays of a small doubly curved patch (:func:`curved_points`) with the LME
    basis (γ = 0.8) of the registry."""
    from scipy.spatial import Delaunay

    from .registry import load_plugin

    xi, P = curved_points(n, seed)
    tri = Delaunay(xi).simplices
    bary, wr = _TRIANGLE_RULE
    V = xi[tri]                                   # (t, 3, 2)
    e1, e2 = V[:, 1] - V[:, 0], V[:, 2] - V[:, 0]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    xg = np.einsum("gk,tkd->tgd", bary, V).reshape(-1, 2)
    wg = (area[:, None] * wr[None, :]).ravel()
    lme = load_plugin("approximants", "lme")(gamma=0.8).fit(xi)
    b = lme.evaluate(xg, order=2)
    H = b.hessians
    basis = np.column_stack([b.values, b.gradients[:, 0], b.gradients[:, 1], H[:, 0, 0],
                             0.5 * (H[:, 0, 1] + H[:, 1, 0]), H[:, 1, 1]])
    rows = np.repeat(np.arange(len(xg)), np.diff(b.indptr))
    X = np.zeros((len(xg), 3))
    T = np.zeros((len(xg), 2, 3))
    S = np.zeros((len(xg), 2, 2, 3))
    for i in range(3):
        np.add.at(X[:, i], rows, basis[:, 0] * P[b.indices, i])
        for al, c in ((0, 1), (1, 2)):
            np.add.at(T[:, al, i], rows, basis[:, c] * P[b.indices, i])
        for (al, be), c in (((0, 0), 3), ((0, 1), 4), ((1, 0), 4), ((1, 1), 5)):
            np.add.at(S[:, al, be, i], rows, basis[:, c] * P[b.indices, i])
    J = np.linalg.norm(np.cross(T[:, 0], T[:, 1]), axis=1)
    return dict(indptr=np.asarray(b.indptr, np.int64), indices=np.asarray(b.indices, np.int64),
                basis=basis, weights=wg * J, chart=np.zeros(len(xg), np.int64), positions=X,
                tangents=T, second=S, orientation=np.ones(len(xg)), n_nodes=len(P),
                node_positions=P)


def check_discrete_energy(physics, patch: dict | None = None, rtol: float = 1e-6,
                          seed: int = 1) -> None:
    """AssertionError naming the rule a physics' discrete energy breaks (see module doc)."""
    name = type(physics).__name__
    patch = curved_patch() if patch is None else patch
    de = physics.discrete_energy(patch)
    rng = np.random.default_rng(seed)
    n = de.n_dofs
    P = patch["node_positions"]
    U = 0.02 * rng.standard_normal(n) + 0.05 * np.resize(np.sin(P).ravel(), n)
    W, R = de.residual(U)
    assert np.isfinite(W) and np.all(np.isfinite(R)), f"{name}: energy or residual not finite"
    K = de.tangent(U).tocsr()
    asym = abs(K - K.T).max()
    scale_k = max(abs(K).max(), 1e-300)
    assert asym <= 1e-10 * scale_k, (
        f"{name}: the tangent is not symmetric (max |K - Kᵀ| = {asym:.3e}, max |K| = "
        f"{scale_k:.3e}); an energy's Hessian must be symmetric.")
    eps = 1e-6 * max(1.0, float(np.abs(U).max()))
    dofs = rng.choice(n, size=min(n, 12), replace=False)
    scale_r = max(float(np.abs(R).max()), 1e-300)
    worst_r, worst_k = (0.0, -1), (0.0, -1, -1)
    for d in dofs:
        E = np.zeros(n)
        E[d] = eps
        fd = (de.energy(U + E) - de.energy(U - E)) / (2 * eps)
        err = abs(fd - R[d]) / scale_r
        worst_r = max(worst_r, (err, int(d)))
        col = (de.residual(U + E)[1] - de.residual(U - E)[1]) / (2 * eps)
        diff = np.abs(col - K[:, d].toarray().ravel()) / scale_k
        i = int(np.argmax(diff))
        worst_k = max(worst_k, (float(diff[i]), i, int(d)))
    assert worst_r[0] <= rtol * 10, (
        f"{name}: the residual disagrees with finite differences of the energy: worst DOF "
        f"{worst_r[1]}, relative error {worst_r[0]:.3e} (R = ∂Π/∂U must hold).")
    assert worst_k[0] <= rtol * 10, (
        f"{name}: the tangent disagrees with finite differences of the residual: worst entry "
        f"K[{worst_k[1]}, {worst_k[2]}], relative error {worst_k[0]:.3e} (K = ∂R/∂U must "
        "hold).")
    if getattr(de, "frame_invariant", False):
        from scipy.spatial.transform import Rotation

        Rm = Rotation.from_rotvec([0.3, -0.5, 0.4]).as_matrix()
        Ur = de.rigid_motion(Rm, np.array([0.2, -0.1, 0.3]))
        Wr, Rr = de.residual(Ur)
        assert abs(Wr) <= 1e-10 * max(abs(W), 1e-300), (
            f"{name}: claims frame invariance but a rigid motion has energy {Wr:.3e} "
            f"(against {W:.3e} at a general state).")
        assert np.abs(Rr).max() <= 1e-8 * scale_r, (
            f"{name}: claims frame invariance but a rigid motion has residual "
            f"{np.abs(Rr).max():.3e} (against {scale_r:.3e}).")
