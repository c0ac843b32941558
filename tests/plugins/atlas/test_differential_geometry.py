"""Pointwise surface geometry on an analytic sphere parametrization."""
import numpy as np
import pytest

from pointatlas_atlas import differential_geometry as dg


def sphere_chart(u, v, R):
    """φ(u, v) = R(sin u cos v, sin u sin v, cos u) and its first/second derivatives."""
    su, cu, sv, cv = np.sin(u), np.cos(u), np.sin(v), np.cos(v)
    T = np.stack([R * np.stack([cu * cv, cu * sv, -su], -1),
                  R * np.stack([-su * sv, su * cv, 0 * u], -1)], axis=1)
    S = np.empty((len(u), 2, 2, 3))
    S[:, 0, 0] = R * np.stack([-su * cv, -su * sv, -cu], -1)
    S[:, 0, 1] = S[:, 1, 0] = R * np.stack([-cu * sv, cu * cv, 0 * u], -1)
    S[:, 1, 1] = R * np.stack([-su * cv, -su * sv, 0 * u], -1)
    return T, S


def test_sphere_curvatures_and_area_element():
    rng = np.random.default_rng(1)
    u, v, R = rng.uniform(0.3, 2.8, 50), rng.uniform(0, 6, 50), 2.0
    T, S = sphere_chart(u, v, R)
    g = dg.surface_geometry(T, S)
    assert np.allclose(g["area_element"], R**2 * np.sin(u))
    assert np.allclose(np.abs(g["mean_curvature"]), 2 / R)
    assert np.allclose(g["gaussian_curvature"], 1 / R**2)
    k = dg.principal_curvatures(g["metric"], g["second_fundamental_form"])
    assert np.allclose(np.abs(k), 1 / R)


def test_cylinder_is_flat():
    # φ(u, v) = (cos u, sin u, v): H = ±1, K = 0
    u = np.linspace(0, 6, 7)
    T = np.stack([np.stack([-np.sin(u), np.cos(u), 0 * u], -1),
                  np.stack([0 * u, 0 * u, 1 + 0 * u], -1)], axis=1)
    S = np.zeros((7, 2, 2, 3))
    S[:, 0, 0] = np.stack([-np.cos(u), -np.sin(u), 0 * u], -1)
    g = dg.surface_geometry(T, S)
    assert np.allclose(np.abs(g["mean_curvature"]), 1) and np.allclose(g["gaussian_curvature"], 0)


def test_unit_normal_rejects_curves():
    with pytest.raises(ValueError, match="R\\^3"):
        dg.unit_normal(np.zeros((3, 1, 3)))
