"""Loads as kit energies (pointatlas_kit.external_work) on an atlas of a sphere made here."""
import numpy as np
import pytest

from pointatlas.errors import ConfigError, InputError
from pointatlas_kit.external_work import (chart_point_quadrature, load_vector,
                                          node_point_quadrature)
from pointatlas_kit.fields import Field, FieldLayout

from ..atlas.test_atlas import make_atlas

PHI = Field("phi", components=1, order=1)
DISP = Field("u", components=3, order=2, value=False)


@pytest.fixture(scope="module")
def sphere_atlas():
    """A Fibonacci sphere of radius 1.5 (500 points), its atlas and order-2 quadrature."""
    from pointatlas_kit.atlas_quadrature import atlas_quadrature

    n = 500
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    t = np.pi * (1 + 5 ** 0.5) * k
    r = np.sqrt(1 - z * z)
    pts = 1.5 * np.column_stack([r * np.cos(t), r * np.sin(t), z])
    atlas = make_atlas(allow_failed_patches=True)
    atlas.partition(pts, keep_basis=True)
    atlas.build_charts()
    atlas.build_quadrature(keep_basis=True, need_second=True)
    return atlas, atlas_quadrature(atlas, order=2)


def test_surface_load_is_the_plain_consistent_force(sphere_atlas):
    """F_a = Σ_g w_g p_a(ξ_g) q_g, written out here with np.add.at, and the resultants:
    Σ_a F_a = ∫ q (partition of unity); a pressure on a closed sphere has no net force and
    the virial Σ_a x_a · F_a = p ∫ (Σ p_a x_a)·n ≈ p R · area."""
    atlas, q = sphere_atlas
    layout = FieldLayout((PHI, DISP), q.n_nodes)
    traction = 0.7 * q.normals + np.array([0.0, 0.0, -0.2])
    F = load_vector(layout, "u", q, traction)
    assert F.shape == (q.n_nodes, 4) and np.all(F[:, 0] == 0)   # only the field's columns
    rows = np.repeat(np.arange(q.n_points), np.diff(q.indptr))
    plain = np.zeros((q.n_nodes, 3))
    np.add.at(plain, q.indices, (q.weights[rows] * q.basis[:, 0])[:, None] * traction[rows])
    assert np.allclose(F[:, 1:], plain, rtol=0, atol=1e-14 * np.abs(plain).max())
    assert np.allclose(F[:, 1:].sum(axis=0), q.weights @ traction, atol=1e-12)
    P = atlas.points_
    # a pressure on a closed sphere: zero net force, virial p R area (x·n = R)
    area = q.weights.sum()
    assert abs(area - 4 * np.pi * 1.5 ** 2) < 2e-3 * area
    Fp = load_vector(FieldLayout((DISP,), q.n_nodes), "u", q, 0.7 * q.normals)
    assert np.abs(Fp.sum(axis=0)).max() < 2e-3 * 0.7 * area
    virial = np.einsum("ai,ai->", P, Fp)
    smoothed = q.interpolation() @ P          # Σ_a p_a x_a: the max-ent smoothing of x
    assert np.isclose(virial, 0.7 * np.einsum("m,mi,mi->", q.weights, smoothed, q.normals),
                      rtol=1e-12)
    assert np.isclose(virial, 0.7 * 1.5 * area, rtol=0.03)


def test_point_load_reproduces_force_and_moment(sphere_atlas):
    """A point force at a projected surface point: Σ F = P, the moment Σ x_a × F_a about
    the centre ≈ x × P (the sampled points x_a are not the charts' control points, so to
    the smoothing of the max-ent basis), and the quadrature point is the projection."""
    from pointatlas_atlas.projection import closest_point

    atlas, q = sphere_atlas
    proj = closest_point(atlas, np.array([[0.3, -0.9, 1.4]]))
    qp = chart_point_quadrature(atlas, proj.chart, proj.xi, np.ones(1))
    force = np.array([1.0, -2.0, 0.5])
    F = load_vector(FieldLayout((DISP,), q.n_nodes), "u", qp, force)
    assert np.allclose(F.sum(axis=0), force, atol=1e-12)
    moment = np.cross(atlas.points_, F).sum(axis=0)
    assert np.allclose(moment, np.cross(qp.positions[0], force), atol=0.05)
    assert np.allclose(qp.positions[0], proj.point[0], atol=1e-8)


def test_line_weights_on_nodes_and_a_scalar_source(sphere_atlas):
    """Weighted node points carry Σ F = t Σ ℓ; a scalar field takes a source the same way."""
    atlas, q = sphere_atlas
    nodes = np.arange(0, 40, 3)
    ell = np.linspace(0.1, 0.2, len(nodes))
    qn = node_point_quadrature(atlas, nodes, ell)
    assert np.allclose(qn.positions, atlas.points_[nodes], atol=1e-6)
    F = load_vector(FieldLayout((PHI,), q.n_nodes), "phi", qn, np.array([2.0]))
    assert np.isclose(F.sum(), 2.0 * ell.sum())


def test_bad_loads_are_refused(sphere_atlas):
    atlas, q = sphere_atlas
    layout = FieldLayout((DISP,), q.n_nodes)
    with pytest.raises(ConfigError, match="no field named 'T'"):
        load_vector(layout, "T", q, np.zeros(3))
    with pytest.raises(ConfigError, match="3 value"):
        load_vector(layout, "u", q, np.zeros(2))
    with pytest.raises(InputError, match="NaN"):
        load_vector(layout, "u", q, np.full(3, np.nan))
    with pytest.raises(InputError, match="one of each"):
        chart_point_quadrature(atlas, [0, 1], np.zeros((2, 2)), np.ones(1))
    with pytest.raises(InputError, match="outside chart"):
        chart_point_quadrature(atlas, [0], np.full((1, 2), 1e3), np.ones(1))
