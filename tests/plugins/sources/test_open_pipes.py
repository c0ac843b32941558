"""Open connected pipes: a ladder of pipes (genus 2) with four open ends at z = ±H."""
import dataclasses
import inspect

import numpy as np
import pytest

from pointatlas.errors import ConfigError
from pointatlas_sources.open_pipes import (
    OpenPipes,
    junction_excess,
    pipes_value_gradient,
    project_to_surface,
)

from .conftest import nn_distances

R, A, B, H, K = 0.45, 2.65, 1.8, 3.0, 0.45  # defaults: radius, half-width, rung offset, ...
GEO = (R, A, B, K)
AXES = [(-A, -H), (-A, H), (A, -H), (A, H)]  # end circles: (x of the axis, z)


@pytest.fixture(scope="module")
def clouds():
    """One structured and one random default cloud (2500 points), rng seed 0."""
    return {s: OpenPipes(n_points=2500, sampling=s).load(np.random.default_rng(0))
            for s in ("structured", "random")}


def test_config_matches_keyword_only_init():
    fields = {f.name: f.default for f in dataclasses.fields(OpenPipes.Config)}
    params = {k: p for k, p in inspect.signature(OpenPipes.__init__).parameters.items()
              if k != "self"}
    assert {k: p.default for k, p in params.items()} == fields
    assert all(p.kind is p.KEYWORD_ONLY for p in params.values())
    assert "\n" not in OpenPipes.description
    pytest.importorskip("omegaconf").OmegaConf.structured(OpenPipes.Config)
    assert 2 * (fields["half_width"] + fields["pipe_radius"]) == pytest.approx(6.2)


def test_gradient_matches_finite_differences():
    X = np.random.default_rng(0).uniform([-3.3, -0.7, -3], [3.3, 0.7, 3], (500, 3))
    eps = 1e-6
    fd = np.column_stack([(pipes_value_gradient(X + eps * e, *GEO)[0]
                           - pipes_value_gradient(X - eps * e, *GEO)[0]) / (2 * eps)
                          for e in np.eye(3)])
    np.testing.assert_allclose(pipes_value_gradient(X, *GEO)[1], fd, atol=1e-7)


def test_ends_are_plain_cylinders():
    """Near z = ±H the surface is exactly (x ∓ a)² + y² = r² (blends far from the ends)."""
    t = np.linspace(0, 2 * np.pi, 50)
    for xc, zc in AXES:
        for dz in (0.0, 0.25):
            z = zc - np.sign(zc) * dz
            X = np.column_stack([xc + R * np.cos(t), R * np.sin(t), np.full_like(t, z)])
            assert np.abs(pipes_value_gradient(X, *GEO)[0]).max() < 1e-14


def _contour(g):
    """Marching-cubes mesh of F = 0 on |z| ≤ H (grid planes at z = ±H), vertices projected."""
    pv = pytest.importorskip("pyvista")
    lo = np.array([-A - R - 0.15, -R - 0.15, -H])
    dims = np.ceil(-2 * lo / g).astype(int) + 1
    grid = pv.ImageData(dimensions=dims, spacing=-2 * lo / (dims - 1), origin=lo)
    grid["F"] = pipes_value_gradient(np.asarray(grid.points), *GEO)[0]
    mesh = grid.contour([0.0], scalars="F").triangulate().clean()
    mesh.points = project_to_surface(np.asarray(mesh.points), *GEO)
    return mesh


def test_topology_and_area_against_a_marching_cubes_mesh():
    """χ(mesh) = V − E + F = −6 (genus 2, four boundary circles); the O(g²) mesh areas,
    Richardson-extrapolated, agree with the reference area (junction formula) to 3e-5."""
    areas = []
    for g in (0.08, 0.04):
        mesh = _contour(g)
        faces = mesh.faces.reshape(-1, 4)[:, 1:]
        edges = np.unique(np.sort(np.vstack([faces[:, [0, 1]], faces[:, [1, 2]],
                                             faces[:, [2, 0]]]), axis=1), axis=0)
        assert mesh.n_points - len(edges) + len(faces) == -6
        areas.append(mesh.area)
    ref = OpenPipes()._area()
    assert ref == pytest.approx(68.74798, abs=2e-4)
    assert abs(areas[1] - ref) < abs(areas[0] - ref) / 3
    assert (4 * areas[1] - areas[0]) / 3 == pytest.approx(ref, rel=3e-5)


def test_junction_excess_is_converged_and_scales_with_r_squared():
    assert junction_excess(1.0) == pytest.approx(-8.343548, abs=3e-5)
    small = OpenPipes(pipe_radius=0.3, blend=0.3)._area()
    plain = 4 * np.pi * 0.3 * (2 * H + 3 * A)
    assert small - plain == pytest.approx(6 * 0.09 * junction_excess(1.0), rel=1e-12)


@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_on_the_surface_with_the_four_end_circles(clouds, sampling):
    pc = clouds[sampling]
    X = pc.points
    assert X.shape == (2500, 3) and len(np.unique(X, axis=0)) == 2500
    assert np.abs(pipes_value_gradient(X, *GEO)[0]).max() < 1e-10
    assert np.abs(X[:, 2]).max() == H
    h = pc.exact["spacing"]
    assert h == pytest.approx(np.sqrt(pc.exact["area"] / 2500))
    for xc, zc in AXES:
        ring = X[(X[:, 2] == zc) & (np.sign(X[:, 0]) == np.sign(xc))]
        np.testing.assert_allclose(np.hypot(ring[:, 0] - xc, ring[:, 1]), R, atol=1e-14)
        assert len(ring) == int(round(2 * np.pi * R / (0.85 * h))) >= 8
        gaps = np.diff(np.sort(np.arctan2(ring[:, 1], ring[:, 0] - xc)))
        assert gaps.max() * R < 1.5 * h  # no hole along the circle
    assert pc.exact["euler_characteristic"] == 2 - 2 * pc.exact["genus"] - 4 == -6
    assert pc.exact["n_boundary_curves"] == 4
    assert pc.markers.shape == (625, 3)
    assert np.abs(pipes_value_gradient(pc.markers, *GEO)[0]).max() < 1e-10


@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_quasi_uniform_and_only_the_end_circles_are_boundary(clouds, sampling):
    """Nearest-neighbour distances within a factor 2.6; the shell's boundary detection
    (angular gaps in the local tangent plane) finds exactly the end-circle points."""
    X = clouds[sampling].points
    d = nn_distances(X)
    assert d.max() / d.min() < 2.6
    assert 0.7 < np.median(d) / clouds[sampling].exact["spacing"] < 1.0
    boundary = pytest.importorskip("pointatlas_atlas.boundary")
    mask = boundary.boundary_mask(X)
    np.testing.assert_array_equal(mask, np.abs(X[:, 2]) == H)
    assert len(boundary.boundary_curves(X, mask)) == 4


def test_seeding(clouds):
    src = OpenPipes(n_points=600, sampling="random", n_markers=150)
    a, b = src.load(np.random.default_rng(3)), src.load(np.random.default_rng(3))
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.markers, b.markers)
    assert not np.allclose(a.points, src.load(np.random.default_rng(4)).points)
    s = OpenPipes(n_points=600)
    np.testing.assert_array_equal(s.load(np.random.default_rng(0)).points,
                                  s.load(np.random.default_rng(1)).points)
    assert not np.allclose(clouds["random"].points, clouds["structured"].points)


@pytest.mark.parametrize("kw, name", [
    (dict(pipe_radius=-0.1), "pipe_radius"),
    (dict(blend=0.5), "blend"),                        # > pipe_radius
    (dict(rung_offset=1.5), "rung_offset"),            # < 2(r + k) = 1.8
    (dict(half_width=1.2), "half_width"),              # < 2r + k
    (dict(half_height=2.8), "half_height"),            # ends not plain cylinders
    (dict(rung_offset=2.4), "half_height"),             # ends too close to the top rung
    (dict(n_points=150), "n_points"),                  # < 8 points around a pipe
    (dict(sampling="grid"), "sampling"),
])
def test_bad_config_names_the_value(kw, name):
    with pytest.raises(ConfigError, match=name):
        OpenPipes(**kw).load(np.random.default_rng(0))
