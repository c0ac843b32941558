"""Collocation boundary elements on a generating curve: elements, quadrature, operators.

The traction is piecewise constant on elements of the curve parameter t (chord-length
fraction, :mod:`.meridian`), collocated at the element mid-parameters (never on the axis).
Each element is integrated on the exact spline geometry with ``gauss_points`` Gauss–Legendre
points. The element that holds the collocation point is split there; on each half
t = t_i ± L w² (w Gauss points on [0, 1]) and the logarithmic singularity of the single layer,
−C ln|t − t_i| with C = 2 (meridional) and 4 (swirl) (:mod:`.ring_kernels`), is subtracted
and integrated in closed form, ∫_0^L ln τ dτ = L ln L − L. The two neighbours of that element
(nearly singular at their shared end) use the same squared-parameter rule clustered towards
that end. Units: lengths as given, 1/μ folded in by the caller.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .meridian import Meridian
from .ring_kernels import double_layer_and_constant, single_layer

#: coefficient of −ln|t − t_i| in (M_rr, M_rz, M_zr, M_zz, M_φφ) at the self point
LOG_COEFFICIENT = np.array([2.0, 0.0, 0.0, 2.0, 4.0])


def element_edges(n: int, spacing: str = "uniform") -> np.ndarray:
    """Parameter edges (n + 1,) of n elements: uniform in t, or ``cosine`` (t = (1 − cos πs)/2,
    refined towards both poles)."""
    s = np.linspace(0.0, 1.0, n + 1)
    return s if spacing == "uniform" else 0.5 * (1.0 - np.cos(np.pi * s))


@dataclass
class Elements:
    """Elements of a meridian: mid-points (collocation), quadrature points and weights
    (arclength), normals, and the per-element ring area 2π∫r dℓ and moment 2π∫r² dℓ."""

    meridian: Meridian
    edges: np.ndarray
    t_mid: np.ndarray
    x_mid: np.ndarray
    n_mid: np.ndarray
    t_q: np.ndarray        # (n, G)
    x_q: np.ndarray        # (n, G, 2)
    n_q: np.ndarray        # (n, G, 2)
    w_q: np.ndarray        # (n, G) arclength weights
    gauss: tuple

    @property
    def n(self) -> int:
        return len(self.t_mid)

    @property
    def ring_area(self) -> np.ndarray:
        return 2.0 * np.pi * np.sum(self.x_q[..., 0] * self.w_q, axis=1)

    @property
    def ring_moment(self) -> np.ndarray:
        return 2.0 * np.pi * np.sum(self.x_q[..., 0] ** 2 * self.w_q, axis=1)

    @property
    def arclength(self) -> np.ndarray:
        """Arclength from the first pole to each element's collocation point."""
        s_edges = np.concatenate([[0.0], np.cumsum(self.w_q.sum(axis=1))])
        half = _arclength(self.meridian, self.edges[:-1], self.t_mid, self.gauss)
        return s_edges[:-1] + half


def _arclength(meridian, t0, t1, gauss):
    xg, wg = gauss
    t = t0[:, None] + (t1 - t0)[:, None] * xg[None, :]
    J = np.linalg.norm(meridian.tangent(t), axis=-1)
    return np.sum(J * wg[None, :], axis=1) * (t1 - t0)


@lru_cache(maxsize=None)
def _gauss01(n: int):
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


def discretise(meridian: Meridian, n_elements: int, gauss_points: int = 8,
               spacing: str = "uniform") -> Elements:
    edges = element_edges(n_elements, spacing)
    g = _gauss01(gauss_points)
    h = np.diff(edges)
    t_q = edges[:-1, None] + h[:, None] * g[0][None, :]
    J = np.linalg.norm(meridian.tangent(t_q), axis=-1)
    t_mid = 0.5 * (edges[:-1] + edges[1:])
    return Elements(meridian, edges, t_mid, meridian.point(t_mid), meridian.normal(t_mid),
                    t_q, meridian.point(t_q), meridian.normal(t_q), J * h[:, None] * g[1],
                    g)


def near_pairs(el: Elements, n_w: int):
    """The self and neighbour pairs (i, e) of collocation points and elements with their
    squared-parameter rules: [(i, e, t (p, q), dt (p, q))] for the self element (split at
    t_i), the left and the right neighbour (clustered at the end nearest x_i)."""
    w, wt = _gauss01(n_w)
    E, ti = el.edges, el.t_mid
    n = el.n
    i = np.arange(n)
    La, Lb = ti - E[:-1], E[1:] - ti
    t_self = np.concatenate([ti[:, None] - La[:, None] * w ** 2,
                             ti[:, None] + Lb[:, None] * w ** 2], axis=1)
    dt_self = np.concatenate([La[:, None] * 2 * w * wt, Lb[:, None] * 2 * w * wt], axis=1)
    h = np.diff(E)
    left, right = i[1:], i[:-1]             # collocation points with a left / right neighbour
    t_left = E[left][:, None] - h[left - 1][:, None] * w ** 2     # element left-1, ends at E[i]
    t_right = E[right + 1][:, None] + h[right + 1][:, None] * w ** 2
    return [(i, i, t_self, dt_self),
            (left, left - 1, t_left, h[left - 1][:, None] * 2 * w * wt),
            (right, right + 1, t_right, h[right + 1][:, None] * 2 * w * wt)]


def single_layer_matrices(el: Elements, n_singular: int = 16):
    """(A (2n, 2n), B (n, n)): the meridional and swirl single-layer operators
    ∫_e M(x_i, y) dℓ (without 1/8πμ); row/column 2i + α with α = 0 radial, 1 axial."""
    n = el.n
    K = single_layer(el.x_mid[:, None, None, :], el.x_q[None, :, :, :])   # (n, n, G, 5)
    S = np.einsum("ijgk,jg->ijk", K, el.w_q)
    for k, (i, e, t, dt) in enumerate(near_pairs(el, n_singular)):
        x = el.meridian.point(t)
        J = np.linalg.norm(el.meridian.tangent(t), axis=-1)
        K = single_layer(el.x_mid[i][:, None, :], x)                      # (p, q, 5)
        val = np.einsum("pqk,pq->pk", K, J * dt)
        if k == 0:                          # the self element: subtract the log singularity
            ti = el.t_mid
            Ji = np.linalg.norm(el.meridian.tangent(ti), axis=-1)
            lg = np.log(np.abs(t - ti[:, None]))
            val += LOG_COEFFICIENT[None, :] * (Ji * np.sum(lg * dt, axis=1))[:, None]
            La, Lb = ti - el.edges[:-1], el.edges[1:] - ti
            exact = La * np.log(La) - La + Lb * np.log(Lb) - Lb
            val -= LOG_COEFFICIENT[None, :] * (Ji * exact)[:, None]
        S[i, e] = val
    A = np.empty((2 * n, 2 * n))
    A[0::2, 0::2], A[0::2, 1::2] = S[..., 0], S[..., 1]
    A[1::2, 0::2], A[1::2, 1::2] = S[..., 2], S[..., 3]
    return A, S[..., 4].copy()


def double_layer_rhs(el: Elements, velocity, n_singular: int = 16) -> np.ndarray:
    """PV ∫ T_ijk v_j n_k dS at the collocation points, (n, 3) as (r, z, φ), for the nodal
    velocity spline ``velocity`` (t → (v_r, v_z, v_φ)); by subtraction of v(x_i) and the
    identity ∫ T_ijk n_k dS = −½ δ_ij on the surface (:mod:`.ring_kernels`)."""
    v0 = velocity(el.t_mid)                                                  # (n, 3)

    def integrand(xi, v0i, x, nq, v):
        D, C = double_layer_and_constant(xi, x, nq)                         # (…, 5), (…, 3)
        out = np.empty(D.shape[:-1] + (3,))
        out[..., 0] = D[..., 0] * v[..., 0] + D[..., 1] * v[..., 1] - C[..., 0] * v0i[..., 0] \
            - D[..., 1] * v0i[..., 1]
        out[..., 1] = D[..., 2] * v[..., 0] + D[..., 3] * v[..., 1] - C[..., 1] * v0i[..., 0] \
            - D[..., 3] * v0i[..., 1]
        out[..., 2] = D[..., 4] * v[..., 2] - C[..., 2] * v0i[..., 2]
        return out

    vq = velocity(el.t_q)                                                    # (n, G, 3)
    F = integrand(el.x_mid[:, None, None, :], v0[:, None, None, :], el.x_q[None],
                  el.n_q[None], vq[None])                                    # (n, n, G, 3)
    S = np.einsum("ijgk,jg->ijk", F, el.w_q)
    for i, e, t, dt in near_pairs(el, n_singular):
        J = np.linalg.norm(el.meridian.tangent(t), axis=-1)
        f = integrand(el.x_mid[i][:, None], v0[i][:, None], el.meridian.point(t),
                      el.meridian.normal(t), velocity(t))
        S[i, e] = np.einsum("pqk,pq->pk", f, J * dt)
    return S.sum(axis=1) - 0.5 * v0
