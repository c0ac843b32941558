"""Gauss rules on simplices of any order, by collapsed (Duffy) tensor products.

The unit simplex T_d = {x ∈ R^d : x_i ≥ 0, Σ x_i ≤ 1} is the image of the cube [0,1]^d under
the collapsed map (Duffy)

    x_d = u_d,  x_{d-1} = u_{d-1}(1 - u_d),  ...,  x_1 = u_1 (1 - u_2) ... (1 - u_d),

whose Jacobian is Π_k (1 - u_k)^{k-1}. Integrating in u_k with a Gauss–Jacobi rule for the
weight (1 - u_k)^{k-1} on [0, 1] and n = ceil((order + 1) / 2) points per direction integrates
every polynomial of total degree ≤ order on T_d exactly (each direction then sees a polynomial
of degree ≤ order after the Jacobian weight is absorbed). Paper 1 §2.6 (thesis L1085) uses
symmetric Gauss rules of orders 1..15 on the Delaunay triangles of each chart; the collapsed
rules have a few more points (order 6: 16 instead of 12) and the same exactness.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.special import roots_jacobi

from pointatlas.errors import ConfigError


@dataclass(frozen=True)
class SimplexRule:
    """Points (n, d) in barycentric-free coordinates on the unit simplex and weights (n,).

    The weights sum to the volume of the unit simplex, 1/d!.
    """

    points: np.ndarray
    weights: np.ndarray
    order: int

    @property
    def n_points(self) -> int:
        return self.weights.shape[0]


def jacobi_rule_unit_interval(n: int, alpha: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss rule on [0, 1] for the weight (1 - u)^alpha (exact to degree 2n - 1).

    From the Gauss–Jacobi rule on [-1, 1] with weight (1 - t)^alpha: u = (1 + t)/2,
    (1 - u)^alpha du = (1 - t)^alpha dt / 2^(alpha + 1).
    """
    t, w = roots_jacobi(n, float(alpha), 0.0)
    return (1.0 + t) / 2.0, w / 2.0 ** (alpha + 1)


def check_order(order) -> int:
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 1:
        raise ConfigError(
            f"quadrature order = {order!r} is invalid; it must be an integer >= 1 (the total "
            "polynomial degree integrated exactly). The thesis uses order 6 (12-point rule)."
        )
    return int(order)


@lru_cache(maxsize=64)
def _simplex_rule(d: int, order: int) -> SimplexRule:
    n = (order + 2) // 2  # ceil((order + 1) / 2)
    us, ws = [], []
    for k in range(1, d + 1):  # direction k carries the weight (1 - u_k)^(k-1)
        u, w = jacobi_rule_unit_interval(n, k - 1)
        us.append(u)
        ws.append(w)
    grids = np.meshgrid(*us, indexing="ij")
    wgrids = np.meshgrid(*ws, indexing="ij")
    U = np.column_stack([g.ravel() for g in grids])  # (n^d, d): column k-1 is u_k
    W = np.prod(np.column_stack([g.ravel() for g in wgrids]), axis=1)
    X = np.empty_like(U)
    scale = np.ones(U.shape[0])
    for k in range(d, 0, -1):  # x_k = u_k Π_{j>k} (1 - u_j)
        X[:, k - 1] = U[:, k - 1] * scale
        scale = scale * (1.0 - U[:, k - 1])
    return SimplexRule(points=X, weights=W, order=order)


def simplex_rule(d: int, order: int) -> SimplexRule:
    """A Gauss rule on the unit d-simplex exact for polynomials of total degree ≤ order."""
    if isinstance(d, bool) or not isinstance(d, (int, np.integer)) or d < 1:
        raise ConfigError(f"simplex dimension d = {d!r} is invalid; it must be an integer >= 1.")
    return _simplex_rule(int(d), check_order(order))


def map_rule_to_simplices(vertices: np.ndarray, rule: SimplexRule) -> tuple[np.ndarray, np.ndarray]:
    """Quadrature points (n_simplices·n_g, d) and weights on physical simplices.

    vertices : (n_simplices, d + 1, d) vertex coordinates. The affine map
    x = v_0 + Σ_k λ_k (v_k - v_0) has Jacobian |det[v_k - v_0]|; weights are multiplied by it.
    Points are ordered simplex-major.
    """
    V = np.asarray(vertices, dtype=np.float64)
    E = V[:, 1:, :] - V[:, :1, :]  # (s, d, d): rows are edge vectors
    if E.shape[1] == 2:  # explicit 2×2 determinant (np.linalg.det loops in LAPACK per simplex)
        det = np.abs(E[:, 0, 0] * E[:, 1, 1] - E[:, 0, 1] * E[:, 1, 0])
    else:
        det = np.abs(np.linalg.det(E))
    pts = V[:, None, 0, :] + np.einsum("gk,skj->sgj", rule.points, E)
    w = det[:, None] * rule.weights[None, :]
    return pts.reshape(-1, V.shape[2]), w.ravel()
