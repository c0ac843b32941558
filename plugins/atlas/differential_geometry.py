"""Differential geometry of a parametrized d-manifold φ: A ⊂ R^d → R^D, pointwise on arrays.

Inputs are the derivatives of the chart at m points (Paper 1 §3.1, thesis L1200):
tangents T[:, α, :] = ∂φ/∂ξ_α (m, d, D), second derivatives S[:, α, β, :] = ∂²φ/∂ξ_α∂ξ_β
(m, d, d, D). Metric a_αβ = φ_α·φ_β, d-volume element J = sqrt(det a) (length for curves,
area for surfaces, volume for 3-manifolds).

Any d, D (second derivatives given): the vector second fundamental form is the normal part
of φ_αβ, II_αβ = φ_αβ − a^{γδ}(φ_αβ·φ_γ) φ_δ; the mean curvature vector is
H⃗ = a^{αβ} II_αβ (a sum of principal curvatures, not an average); by the Gauss equation the
scalar curvature is R = |H⃗|² − a^{αγ} a^{βδ} II_αβ·II_γδ. For a curve (d = 1) H⃗ is the
curvature vector κ n and |H⃗| the curvature κ; for a surface (d = 2) the Gaussian curvature is
K = R/2.

Hypersurfaces (D = d + 1): unit normal n with (φ_1, …, φ_d, n) positively oriented
(n = φ_1 × φ_2 / |φ_1 × φ_2| for a surface in R^3, the tangent turned by +90° for a plane
curve), scalar second fundamental form b_αβ = φ_αβ · n, shape operator a^{-1} b, mean
curvature H = tr(a^{-1} b) = Σ κ_i (the thesis convention of the Willmore energy
∫H² dA = 16π on a unit sphere, L1085) and Gauss–Kronecker curvature det b / det a = Π κ_i
(= K for d = 2). The sign of H follows the orientation of n; H² and K do not depend on it.
The atlas orients its charts alike (:mod:`.orientation`) and passes the chart signs as
``orientation`` (a factor ±1 on n per point).

:func:`surface_geometry` returns a :class:`Geometry` dict: ``metric`` and ``area_element``
always, the thesis quantities of a surface in R^3 (``normal``, ``second_fundamental_form``,
``mean_curvature``, ``gaussian_curvature``) at once, everything else on first access; a
quantity the dimensions do not define raises :class:`InputError` saying which it needs.
"""
from __future__ import annotations

import numpy as np

from pointatlas.errors import InputError


def chart_derivatives(basis, control_points: np.ndarray, order: int = 2):
    """φ, Dφ and D²φ at the evaluation points from basis functions p_a and control points P_a.

    φ(ξ) = Σ_a p_a(ξ) P_a (thesis Eq. 2). ``basis`` is a :class:`pointatlas.basis.BasisFunctions`
    with gradients (order ≥ 1) and Hessians (order 2). Returns (X (m, D), T (m, d, D) or None,
    S (m, d, d, D) or None).
    """
    from scipy.sparse import csr_matrix

    m, n = basis.n_points, control_points.shape[0]
    shape = (m, n)

    def apply(vals):
        return csr_matrix((vals, basis.indices, basis.indptr), shape=shape) @ control_points

    X = apply(basis.values)
    T = S = None
    if order >= 1:
        d = basis.gradients.shape[1]
        T = np.stack([apply(basis.gradients[:, k]) for k in range(d)], axis=1)
    if order >= 2:
        d = basis.hessians.shape[1]
        S = np.empty((m, d, d, control_points.shape[1]))
        for k in range(d):
            for j in range(k, d):
                S[:, k, j] = apply(basis.hessians[:, k, j])
                S[:, j, k] = S[:, k, j]
    return X, T, S


def metric(T: np.ndarray) -> np.ndarray:
    """First fundamental form a_αβ = φ_α · φ_β, (m, d, d)."""
    return np.einsum("mai,mbi->mab", T, T)


def area_element(T: np.ndarray) -> np.ndarray:
    """J = sqrt(det a), the d-volume element of the chart (thesis §3.4), (m,)."""
    return np.sqrt(np.clip(np.linalg.det(metric(T)), 0.0, None))


def _dims(T: np.ndarray) -> str:
    return f"d={T.shape[1]}, D={T.shape[2]}"


def unit_normal(T: np.ndarray) -> np.ndarray:
    """Unit normal of a hypersurface (d = D − 1), (m, D); (φ_1, …, φ_d, n) is positively
    oriented: n = φ_1 × φ_2 / |φ_1 × φ_2| in R^3, (−φ'_y, φ'_x)/|φ'| for a plane curve.

    General d: n_i = (−1)^(d+i) det(Dφ without column i) (Laplace expansion of
    det[φ_1; …; φ_d; n] along its last row, which is then |n|² > 0), normalised.
    """
    d, D = T.shape[1], T.shape[2]
    if D != d + 1:
        raise InputError(
            f"unit_normal needs a hypersurface, D = d + 1 (a surface (d=2) in R^3, a curve (d=1) "
            f"in R^2, a 3-manifold in R^4); got {_dims(T)}: the normal space has dimension "
            f"{D - d}, so no single unit normal exists.")
    if d == 2:
        c = np.cross(T[:, 0, :], T[:, 1, :])
    elif d == 1:
        c = np.column_stack([-T[:, 0, 1], T[:, 0, 0]])
    else:
        cols = np.arange(D)
        c = np.stack([(-1.0) ** (d + i) * np.linalg.det(T[:, :, cols != i])
                      for i in range(D)], axis=1)
    return c / np.linalg.norm(c, axis=1, keepdims=True)


def second_fundamental_form(S: np.ndarray, n: np.ndarray) -> np.ndarray:
    """b_αβ = φ_αβ · n, (m, d, d)."""
    return np.einsum("mabi,mi->mab", S, n)


def shape_operator(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Mixed components of the Weingarten map, a^{-1} b, (m, d, d)."""
    return np.linalg.solve(a, b)


def mean_curvature(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """H = tr(a^{-1} b) = Σ κ_i (not averaged), (m,)."""
    return np.trace(shape_operator(a, b), axis1=1, axis2=2)


def gaussian_curvature(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """det b / det a = Π κ_i: the Gaussian curvature K of a surface (d = 2), the
    Gauss–Kronecker curvature of a hypersurface, the signed curvature of a plane curve."""
    return np.linalg.det(b) / np.linalg.det(a)


def principal_curvatures(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Principal curvatures κ_1 ≥ … ≥ κ_d (m, d): eigenvalues of a^{-1} b (for d = 2 the roots
    of κ² − H κ + K = 0)."""
    if a.shape[1] != 2:
        # a^{-1} b is self-adjoint for a: eigenvalues of L^{-1} b L^{-T}, a = L Lᵀ
        Linv = np.linalg.inv(np.linalg.cholesky(a))
        sym = Linv @ b @ np.swapaxes(Linv, 1, 2)
        return np.linalg.eigvalsh(sym)[:, ::-1]
    H = mean_curvature(a, b)
    K = gaussian_curvature(a, b)
    disc = np.sqrt(np.clip(H**2 / 4.0 - K, 0.0, None))
    return np.column_stack([H / 2.0 + disc, H / 2.0 - disc])


def vector_second_fundamental_form(T: np.ndarray, S: np.ndarray) -> np.ndarray:
    """II_αβ = φ_αβ − a^{γδ}(φ_αβ·φ_γ) φ_δ, the normal part of φ_αβ, (m, d, d, D); any d, D."""
    a = metric(T)
    proj = np.einsum("mabi,mgi->mabg", S, T)                       # φ_αβ·φ_γ
    coef = np.einsum("mgd,mabg->mabd", np.linalg.inv(a), proj)     # a^{γδ}(φ_αβ·φ_γ)
    return S - np.einsum("mabd,mdi->mabi", coef, T)


def mean_curvature_vector(a: np.ndarray, II: np.ndarray) -> np.ndarray:
    """H⃗ = a^{αβ} II_αβ, (m, D): for a curve the curvature vector, for a hypersurface H n."""
    return np.einsum("mab,mabi->mi", np.linalg.inv(a), II)


def scalar_curvature(a: np.ndarray, II: np.ndarray) -> np.ndarray:
    """R = |H⃗|² − a^{αγ} a^{βδ} II_αβ·II_γδ (Gauss equation), (m,); 2K for a surface,
    d(d − 1)/ρ² on a round d-sphere of radius ρ, 0 for a curve."""
    ainv = np.linalg.inv(a)
    Hv = np.einsum("mab,mabi->mi", ainv, II)
    sq = np.einsum("mag,mbd,mabi,mgdi->m", ainv, ainv, II, II)
    return np.einsum("mi,mi->m", Hv, Hv) - sq


#: which dimensions each quantity of :class:`Geometry` needs (for the error message)
REQUIREMENTS = {
    "normal": "a hypersurface, D = d + 1 (surface in R^3, curve in R^2, 3-manifold in R^4)",
    "second_fundamental_form": "a hypersurface, D = d + 1 (it is the scalar b_αβ = φ_αβ·n; "
                               "use 'vector_second_fundamental_form' in higher codimension)",
    "mean_curvature": "a hypersurface, D = d + 1 (signed H; use 'mean_curvature_squared' "
                      "or 'mean_curvature_vector' in any codimension)",
    "gauss_kronecker_curvature": "a hypersurface, D = d + 1",
    "principal_curvatures": "a hypersurface, D = d + 1",
    "gaussian_curvature": "a surface, d = 2 (any D; use 'scalar_curvature' for d ≥ 3)",
    "curvature": "a curve, d = 1 (any D)",
    "vector_second_fundamental_form": "second derivatives only (any d, D)",
    "mean_curvature_vector": "second derivatives only (any d, D)",
    "mean_curvature_squared": "second derivatives only (any d, D)",
    "scalar_curvature": "second derivatives only (any d, D)",
}


#: quantities whose sign follows the orientation of n (refused on a non-orientable manifold;
#: the Gauss–Kronecker curvature only for odd d, where det(−b) = −det b)
ORIENTED = ("normal", "second_fundamental_form", "mean_curvature", "principal_curvatures",
            "gauss_kronecker_curvature")


class Geometry(dict):
    """Pointwise geometry at m points; quantities beyond the eager ones are computed on first
    access (module docstring). Asking for one the dimensions or the data do not allow raises
    :class:`InputError` naming what it needs."""

    def __init__(self, T: np.ndarray, S: np.ndarray | None, eager: dict,
                 orientation: np.ndarray | None = None, unoriented: str | None = None):
        super().__init__(eager)
        self._T, self._S = T, S
        self._sign, self._unoriented = orientation, unoriented

    def __missing__(self, key):
        T, S = self._T, self._S
        d, D = T.shape[1], T.shape[2]
        if key not in REQUIREMENTS:
            raise KeyError(f"{key!r} is not a geometric quantity; known: "
                           f"{sorted(set(self) | set(REQUIREMENTS))}.")
        hyper = D == d + 1
        ok = {"normal": hyper, "second_fundamental_form": hyper, "mean_curvature": hyper,
              "gauss_kronecker_curvature": hyper, "principal_curvatures": hyper,
              "gaussian_curvature": d == 2, "curvature": d == 1}.get(key, True)
        if not ok:
            raise InputError(f"geometry[{key!r}] needs {REQUIREMENTS[key]}; this manifold has "
                             f"{_dims(T)}.")
        if self._unoriented and key in ORIENTED and (key != "gauss_kronecker_curvature"
                                                     or d % 2 == 1):
            raise InputError(f"geometry[{key!r}] needs an orientation: {self._unoriented}")
        if S is None and key != "normal":
            raise InputError(f"geometry[{key!r}] needs second derivatives of the charts; build "
                             "the quadrature with need_second=True.")
        self[key] = value = self._compute(key)
        return value

    def _compute(self, key: str) -> np.ndarray:
        T, S, a = self._T, self._S, self["metric"]
        if key == "normal":
            n = unit_normal(T)
            return n if self._sign is None else n * self._sign[:, None]
        if key == "second_fundamental_form":
            return second_fundamental_form(S, self["normal"])
        if key == "mean_curvature":
            return mean_curvature(a, self["second_fundamental_form"])
        if key == "gauss_kronecker_curvature" or (key == "gaussian_curvature"
                                                  and T.shape[2] == T.shape[1] + 1):
            # det b is even in n for even d: the unsigned chart normal serves unoriented atlases
            b = (second_fundamental_form(S, unit_normal(T)) if self._unoriented
                 else self["second_fundamental_form"])
            return gaussian_curvature(a, b)
        if key == "principal_curvatures":
            return principal_curvatures(a, self["second_fundamental_form"])
        if key == "vector_second_fundamental_form":
            return vector_second_fundamental_form(T, S)
        if key == "mean_curvature_vector":
            return mean_curvature_vector(a, self["vector_second_fundamental_form"])
        if key == "mean_curvature_squared":
            Hv = self["mean_curvature_vector"]
            return np.einsum("mi,mi->m", Hv, Hv)
        if key == "curvature":
            return np.sqrt(self["mean_curvature_squared"])
        if key == "scalar_curvature":
            return scalar_curvature(a, self["vector_second_fundamental_form"])
        if key == "gaussian_curvature":  # d = 2 in codimension > 1: K = R/2
            return 0.5 * self["scalar_curvature"]
        raise KeyError(key)  # pragma: no cover - REQUIREMENTS and _compute agree


def surface_geometry(T: np.ndarray, S: np.ndarray | None, orientation: np.ndarray | None = None,
                     unoriented: str | None = None) -> Geometry:
    """Pointwise geometry of the chart derivatives T (m, d, D), S (m, d, d, D) or None.

    ``metric`` and ``area_element`` (the d-volume element) always; for a surface in R^3 with S
    given also ``normal``, ``second_fundamental_form``, ``mean_curvature`` (H = κ1 + κ2) and
    ``gaussian_curvature`` at once; other quantities (:data:`REQUIREMENTS`) on access.

    orientation : (m,) ±1 multiplying the normal of each point (the atlas's chart signs,
        :mod:`.orientation`), so n, b and H are those of one orientation; K, H² unchanged.
    unoriented : on a non-orientable manifold, why: the :data:`ORIENTED` quantities then
        raise InputError with it, the orientation-free ones are computed as usual.
    """
    a = metric(T)
    eager = {"metric": a, "area_element": np.sqrt(np.clip(np.linalg.det(a), 0.0, None))}
    if S is not None and T.shape[1] == 2 and T.shape[2] == 3:
        n = unit_normal(T)
        if orientation is not None:
            n = n * orientation[:, None]
        b = second_fundamental_form(S, n)
        eager.update(gaussian_curvature=gaussian_curvature(a, b))
        if not unoriented:
            eager.update(normal=n, second_fundamental_form=b, mean_curvature=mean_curvature(a, b))
    return Geometry(T, S, eager, orientation, unoriented)


#: the same, under a name that does not suggest d = 2
manifold_geometry = surface_geometry
