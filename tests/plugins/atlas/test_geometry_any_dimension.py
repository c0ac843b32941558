"""Pointwise geometry of curves (d = 1), 3-manifolds in R^4 and a surface in R^4, analytically."""
import numpy as np
import pytest

from pointatlas.errors import InputError
from pointatlas_atlas import differential_geometry as dg
from pointatlas_atlas.partition import embedding_defects


def circle_chart(t, R):
    c, s = np.cos(t), np.sin(t)
    T = R * np.stack([-s, c], -1)[:, None, :]
    S = -R * np.stack([c, s], -1)[:, None, None, :]
    return T, S


def helix_chart(t, r, c):
    T = np.stack([-r * np.sin(t), r * np.cos(t), c + 0 * t], -1)[:, None, :]
    S = np.stack([-r * np.cos(t), -r * np.sin(t), 0 * t], -1)[:, None, None, :]
    return T, S


def s3_graph_chart(u, R):
    """φ(u) = (u, f(u)), f = sqrt(R² − |u|²): the upper half of S^3 ⊂ R^4 over the ball |u| < R."""
    f = np.sqrt(R**2 - np.sum(u**2, axis=1))
    m = len(u)
    T = np.zeros((m, 3, 4))
    T[:, :, :3] = np.eye(3)
    T[:, :, 3] = -u / f[:, None]
    S = np.zeros((m, 3, 3, 4))
    S[..., 3] = -np.eye(3) / f[:, None, None] - u[:, :, None] * u[:, None, :] / f[:, None, None] ** 3
    return T, S, f


def clifford_torus_chart(u, v, a, b):
    """φ = (a cos u, a sin u, b cos v, b sin v): a flat torus in R^4 (codimension 2)."""
    z = 0 * u
    T = np.stack([np.stack([-a * np.sin(u), a * np.cos(u), z, z], -1),
                  np.stack([z, z, -b * np.sin(v), b * np.cos(v)], -1)], axis=1)
    S = np.zeros((len(u), 2, 2, 4))
    S[:, 0, 0] = np.stack([-a * np.cos(u), -a * np.sin(u), z, z], -1)
    S[:, 1, 1] = np.stack([z, z, -b * np.cos(v), -b * np.sin(v)], -1)
    return T, S


def test_plane_circle_is_a_hypersurface():
    t, R = np.linspace(0, 6, 9), 2.0
    g = dg.surface_geometry(*circle_chart(t, R))
    np.testing.assert_allclose(g["area_element"], R)          # length element |φ'|
    np.testing.assert_allclose(g["curvature"], 1 / R)
    np.testing.assert_allclose(g["mean_curvature_squared"], 1 / R**2)
    # (φ', n) positively oriented: n is the tangent turned by +90°, the inward normal here,
    # so the signed curvature b/a is +1/R
    np.testing.assert_allclose(g["normal"], -np.stack([np.cos(t), np.sin(t)], -1), atol=1e-14)
    np.testing.assert_allclose(g["mean_curvature"], 1 / R)
    np.testing.assert_allclose(g["scalar_curvature"], 0, atol=1e-14)
    with pytest.raises(InputError, match="d = 2"):
        g["gaussian_curvature"]


def test_helix_curvature_and_no_normal_in_codimension_two():
    t, r, c = np.linspace(0, 9, 11), 1.5, 0.4
    g = dg.surface_geometry(*helix_chart(t, r, c))
    np.testing.assert_allclose(g["area_element"], np.hypot(r, c))
    np.testing.assert_allclose(g["curvature"], r / (r**2 + c**2))
    # the curvature vector points to the axis
    k = g["mean_curvature_vector"]
    np.testing.assert_allclose(k / np.linalg.norm(k, axis=1, keepdims=True),
                               -np.stack([np.cos(t), np.sin(t), 0 * t], -1), atol=1e-14)
    for key in ("normal", "mean_curvature", "second_fundamental_form"):
        with pytest.raises(InputError, match="D = d \\+ 1"):
            g[key]
    with pytest.raises(InputError, match="R\\^3"):
        dg.unit_normal(helix_chart(t, r, c)[0])


def test_three_sphere_in_r4():
    rng = np.random.default_rng(0)
    R = 1.7
    u = rng.uniform(-0.5, 0.5, (40, 3))
    T, S, f = s3_graph_chart(u, R)
    g = dg.surface_geometry(T, S)
    np.testing.assert_allclose(g["area_element"], R / f)     # volume element of the graph
    n = g["normal"]
    np.testing.assert_allclose(np.abs(np.sum(n * np.column_stack([u, f]), 1)) / R, 1, atol=1e-13)
    assert np.allclose(np.einsum("mai,mi->ma", T, n), 0, atol=1e-13)
    np.testing.assert_allclose(np.abs(g["mean_curvature"]), 3 / R)
    np.testing.assert_allclose(np.abs(g["principal_curvatures"]), 1 / R)
    np.testing.assert_allclose(np.abs(g["gauss_kronecker_curvature"]), 1 / R**3)
    np.testing.assert_allclose(g["scalar_curvature"], 6 / R**2)
    np.testing.assert_allclose(g["mean_curvature_squared"], 9 / R**2)
    with pytest.raises(InputError, match="d = 2"):
        g["gaussian_curvature"]
    with pytest.raises(InputError, match="d = 1"):
        g["curvature"]


def test_flat_torus_in_r4_codimension_two():
    u, v, a, b = np.linspace(0, 6, 7), np.linspace(1, 4, 7), 1.0, 0.6
    g = dg.surface_geometry(*clifford_torus_chart(u, v, a, b))
    np.testing.assert_allclose(g["area_element"], a * b)
    np.testing.assert_allclose(g["gaussian_curvature"], 0, atol=1e-13)   # Gauss equation
    np.testing.assert_allclose(g["mean_curvature_squared"], 1 / a**2 + 1 / b**2)
    with pytest.raises(InputError, match="hypersurface"):
        g["normal"]


def test_geometry_without_second_derivatives_says_so():
    T, _ = circle_chart(np.zeros(2), 1.0)
    g = dg.surface_geometry(T, None)
    assert g["normal"].shape == (2, 2)
    with pytest.raises(InputError, match="need_second=True"):
        g["curvature"]
    with pytest.raises(KeyError):
        g["no_such_quantity"]


def test_unit_normal_generalises_the_cross_product():
    rng = np.random.default_rng(2)
    T = rng.standard_normal((5, 2, 3))
    c = np.cross(T[:, 0], T[:, 1])
    np.testing.assert_allclose(dg.unit_normal(T), c / np.linalg.norm(c, axis=1, keepdims=True))
    T4 = rng.standard_normal((5, 3, 4))
    n = dg.unit_normal(T4)
    assert np.allclose(np.einsum("mai,mi->ma", T4, n), 0, atol=1e-12)
    assert (np.linalg.det(np.concatenate([T4, n[:, None, :]], axis=1)) > 0).all()


def test_embedding_defects_of_curves_and_solids():
    t = np.linspace(-1, 1, 60)
    curve = np.column_stack([t, 0.2 * t**2, 0.1 * t**3])
    ok = embedding_defects(curve, t[:, None])
    assert ok["flip_fraction"] == 0 and ok["stress"] < 0.01 and ok["distortion"] < 1.3
    folded = embedding_defects(curve, np.abs(t)[:, None])
    assert folded["flip_fraction"] > 0
    rng = np.random.default_rng(1)
    u = rng.uniform(-1, 1, (400, 3))
    flat = np.column_stack([u, 0.05 * np.sum(u**2, 1)])      # a gently curved 3-patch in R^4
    ok3 = embedding_defects(flat, u)
    assert ok3["flip_fraction"] == 0 and ok3["stress"] < 0.01
    fold3 = embedding_defects(flat, np.column_stack([np.abs(u[:, 0]), u[:, 1:]]))
    assert fold3["flip_fraction"] > 0
