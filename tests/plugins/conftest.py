"""Small surface patches built without the atlas (for the kit and the shell): LME on a
parameter grid, Gauss points on its Delaunay triangles, reference geometry X = Σ p_a P_a
(so linear reproduction is exact)."""
import numpy as np
import pytest
from scipy.sparse import csr_matrix
from scipy.spatial import Delaunay

import pointatlas
from pointatlas_atlas.quadrature import map_rule_to_simplices, simplex_rule
from pointatlas_physics.kirchhoff_love.material import ShellMaterial
from pointatlas_kit.atlas_quadrature import AtlasQuadrature


def lme_patch(params: np.ndarray, surface, order: int = 4, n_groups: int = 3):
    """(AtlasQuadrature, P): LME basis on parameter nodes params (n, 2), nodes P = surface(params)."""
    lme = pointatlas.load_plugin("approximants", "lme")(gamma=0.8).fit(params)
    tri = Delaunay(params).simplices
    xi, wg = map_rule_to_simplices(params[tri], simplex_rule(2, order))
    bf = lme.evaluate(xi, order=2)
    P = surface(params)
    T = np.stack([bf.gradient_csr(len(P), k) @ P for k in range(2)], axis=1)
    S = np.empty((len(xi), 2, 2, 3))
    for a in range(2):
        for b in range(2):
            H = csr_matrix((bf.hessians[:, a, b], bf.indices, bf.indptr), shape=(len(xi), len(P)))
            S[:, a, b] = H @ P
    J = np.linalg.norm(np.cross(T[:, 0], T[:, 1]), axis=1)
    group = np.minimum((xi[:, 0] - xi[:, 0].min()) / np.ptp(xi[:, 0]) * n_groups,
                       n_groups - 1).astype(int)
    Hs = bf.hessians
    basis = np.column_stack([bf.values, bf.gradients[:, 0], bf.gradients[:, 1], Hs[:, 0, 0],
                             0.5 * (Hs[:, 0, 1] + Hs[:, 1, 0]), Hs[:, 1, 1]])
    q = AtlasQuadrature(indptr=bf.indptr, indices=bf.indices, basis=basis, weights=wg * J,
                        chart=group, positions=bf.to_csr(len(P)) @ P, tangents=T, second=S,
                        orientation=np.ones(len(xi)), n_nodes=len(P))
    return q, P


def grid(n1, n2, l1, l2, jitter=0.0, seed=0):
    g1, g2 = np.linspace(0, l1, n1), np.linspace(0, l2, n2)
    p = np.array(np.meshgrid(g1, g2, indexing="ij")).reshape(2, -1).T
    if jitter:
        rng = np.random.default_rng(seed)
        inner = (p[:, 0] > 0) & (p[:, 0] < l1) & (p[:, 1] > 0) & (p[:, 1] < l2)
        p[inner] += jitter * rng.uniform(-1, 1, (inner.sum(), 2)) * min(l1 / n1, l2 / n2)
    return p


RADIUS = 1.5


def cylinder(params):
    th, z = params[:, 0], params[:, 1]
    return np.column_stack([RADIUS * np.cos(th), RADIUS * np.sin(th), z])


def polynomial_plate(order: int = 20):
    """Unit square, 6 'nodes' with basis 1, x, y, x², xy, y² (exact quadratic fields), X = (x, y, 0)."""
    sq = np.array([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]]], float)
    xi, w = map_rule_to_simplices(sq, simplex_rule(2, order))
    x, y = xi[:, 0], xi[:, 1]
    m = len(w)
    o, z = np.ones(m), np.zeros(m)
    cols = [  # p, p_1, p_2, p_11, p_12, p_22 for each node
        (o, z, z, z, z, z), (x, o, z, z, z, z), (y, z, o, z, z, z),
        (x * x, 2 * x, z, 2 * o, z, z), (x * y, y, x, z, o, z), (y * y, z, 2 * y, z, z, 2 * o)]
    basis = np.stack([np.column_stack(c) for c in cols], axis=1).reshape(-1, 6)
    T = np.zeros((m, 2, 3))
    T[:, 0, 0] = 1.0
    T[:, 1, 1] = 1.0
    q = AtlasQuadrature(indptr=np.arange(m + 1) * 6, indices=np.tile(np.arange(6), m),
                        basis=basis, weights=w, chart=np.zeros(m, int),
                        positions=np.column_stack([xi, np.zeros(m)]), tangents=T,
                        second=np.zeros((m, 2, 2, 3)), orientation=np.ones(m), n_nodes=6)
    return q, xi


@pytest.fixture(scope="session")
def material():
    return ShellMaterial(young_modulus=2.0e3, poisson_ratio=0.3, thickness=0.05)


@pytest.fixture(scope="session")
def cylinder_patch():
    return lme_patch(grid(7, 7, 1.0, 1.2, jitter=0.15), cylinder)


@pytest.fixture(scope="session")
def flat_patch():
    return lme_patch(grid(6, 6, 1.0, 1.0, jitter=0.15, seed=1),
                     lambda p: np.column_stack([p, np.zeros(len(p))]))


@pytest.fixture(scope="session")
def make_polynomial_plate():
    return polynomial_plate


