"""Boundary detection, boundary curves and outward conormals (Paper 1 §4.1.2)."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import InputError
from pointatlas_atlas.boundary import (boundary_curves, boundary_mask, is_closed_curve,
                                       outward_conormals)

TOL = 1e-9


def exact_boundary(name, kw, pc):
    """Boundary points from the known parametrisation."""
    X, P = pc.points, pc.parameters
    model = kw.get("model", "full")
    if name == "hemisphere":
        m = np.abs(P[:, 0] - np.pi / 2) < TOL
        if kw.get("hole_angle_deg", 0) > 0:
            m |= np.abs(P[:, 0] - P[:, 0].min()) < TOL
        if model == "quarter":
            m |= (np.abs(X[:, 0]) < TOL) | (np.abs(X[:, 1]) < TOL)
        return m
    m = np.zeros(len(X), dtype=bool)
    for c in (0, 1):
        if name == "cylinder" and model == "full" and c == 0:
            continue  # periodic in phi
        m |= (np.abs(P[:, c] - P[:, c].min()) < TOL) | (np.abs(P[:, c] - P[:, c].max()) < TOL)
    return m


CASES = [("square_plate", {}), ("square_plate", {"model": "quarter"}),
         ("scordelis_lo_roof", {}), ("scordelis_lo_roof", {"model": "quarter"}),
         ("hemisphere", {}), ("hemisphere", {"hole_angle_deg": 18.0}),
         ("hemisphere", {"model": "quarter"}),
         ("hemisphere", {"model": "quarter", "hole_angle_deg": 18.0}),
         ("cylinder", {}), ("cylinder", {"model": "quarter"}), ("cylinder", {"model": "eighth"})]


def load(name, kw, sampling, n=500, seed=0):
    cls = pointatlas.load_plugin("sources", name)
    return cls(n_points=n, sampling=sampling, **kw).load(np.random.default_rng(seed))


@pytest.mark.parametrize("name, kw", CASES)
@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_mask_finds_exactly_the_boundary_and_its_curves(name, kw, sampling):
    pc = load(name, kw, sampling)
    mask = boundary_mask(pc.points)
    truth = exact_boundary(name, kw, pc)
    np.testing.assert_array_equal(mask, truth)
    curves = boundary_curves(pc.points, mask)
    assert len(curves) == pc.exact["n_boundary_curves"]
    assert sorted(np.concatenate(curves).tolist()) == np.flatnonzero(mask).tolist()
    h = pc.exact["spacing"]
    for c in curves:
        assert is_closed_curve(pc.points, c)
        steps = np.linalg.norm(np.diff(pc.points[c], axis=0), axis=1)
        assert steps.max() < 2.5 * h  # ordered along the curve: consecutive points are near


def test_closed_surface_has_no_boundary_and_open_curve_is_open():
    X = pointatlas.load_plugin("sources", "sphere")(n_points=800).load(
        np.random.default_rng(0)).points
    assert not boundary_mask(X).any()
    assert boundary_curves(X, np.zeros(len(X), bool)) == []
    plate = load("square_plate", {}, "structured").points
    edge = np.flatnonzero(np.abs(plate[:, 0] + 5) < TOL)  # one side only: an open curve
    mask = np.zeros(len(plate), bool)
    mask[edge] = True
    (curve,) = boundary_curves(plate, mask)
    assert not is_closed_curve(plate, curve)
    assert np.all(np.diff(plate[curve, 1]) > 0) or np.all(np.diff(plate[curve, 1]) < 0)


def test_random_interior_is_not_flagged_across_seeds():
    for seed in range(4):
        pc = load("square_plate", {"model": "quarter"}, "random", n=900, seed=seed)
        np.testing.assert_array_equal(boundary_mask(pc.points),
                                      exact_boundary("square_plate", {}, pc))


def test_plate_conormals_are_edge_normals_and_corner_bisectors():
    X = load("square_plate", {}, "random", n=400).points
    mask = boundary_mask(X)
    nu = outward_conormals(X, mask)
    assert np.all(nu[~mask] == 0)
    np.testing.assert_allclose(np.linalg.norm(nu[mask], axis=1), 1.0, atol=1e-12)
    corner = (np.abs(X[:, 0]) > 5 - TOL) & (np.abs(X[:, 1]) > 5 - TOL)
    edge = mask & ~corner
    expected = np.where(np.abs(X[:, :2]) > 5 - TOL, np.sign(X[:, :2]), 0.0)
    np.testing.assert_allclose(nu[edge, :2], expected[edge], atol=1e-9)
    np.testing.assert_allclose(nu[corner, :2], expected[corner] / np.sqrt(2), atol=1e-9)
    np.testing.assert_allclose(nu[:, 2], 0.0, atol=1e-12)


@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_hemisphere_conormals_tangent_and_outward(sampling):
    pc = load("hemisphere", {"hole_angle_deg": 18.0}, sampling, n=1500)
    X = pc.points
    mask = boundary_mask(X)
    nu = outward_conormals(X, mask)[mask]
    P = X[mask] / 10.0
    # exact: -e_z on the equator, towards the pole (e_theta reversed) on the hole edge
    rho = np.hypot(P[:, 0], P[:, 1])
    e_theta = np.column_stack([P[:, 2] * P[:, 0] / rho, P[:, 2] * P[:, 1] / rho, -rho])
    on_equator = np.abs(P[:, 2]) < TOL
    expected = np.where(on_equator[:, None], e_theta, -e_theta)
    assert np.abs(np.einsum("ij,ij->i", nu, P)).max() < 0.01  # tangent to the sphere
    assert np.einsum("ij,ij->i", nu, expected).min() > 0.995


def test_bad_input():
    with pytest.raises(InputError, match="shape"):
        boundary_mask(np.zeros((20, 2)))
    with pytest.raises(InputError, match="n_neighbors"):
        boundary_mask(np.random.default_rng(0).random((8, 3)))
