"""Closest-point projection onto the atlas of a unit sphere and the blended map π(x)."""
import numpy as np
import pytest
from scipy.spatial import cKDTree

import pointatlas
from pointatlas.errors import InputError
from pointatlas_atlas.atlas import Atlas, AtlasSettings
from pointatlas_atlas.projection import (
    blended_map,
    candidate_pairs,
    closest_point,
    newton_on_chart,
)

OFFSET = 0.05


@pytest.fixture(scope="module")
def sphere_atlas():
    s = AtlasSettings()
    atlas = Atlas(
        s,
        make_embedder=lambda: pointatlas.load_plugin("embedders", "pca")(n_components=2),
        make_lme=lambda: pointatlas.load_plugin("approximants", "lme")(
            gamma=s.gamma_lme, tol=s.tol_lme, outside="flag"),
        make_pu=lambda: pointatlas.load_plugin("approximants", "shepard")(
            gamma=s.gamma_pu, tol=s.tol_pu, outside="flag"),
    )
    points = pointatlas.load_plugin("sources", "sphere")(n_points=1500).load(
        np.random.default_rng(0)).points
    atlas.partition(points)
    atlas.build_charts()
    return atlas


@pytest.fixture(scope="module")
def off_surface():
    """Unit directions u and points x = (1 ± OFFSET) u, with the side s = ±1."""
    rng = np.random.default_rng(1)
    u = rng.standard_normal((300, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    side = rng.choice([-1.0, 1.0], len(u))
    return u, u * (1.0 + OFFSET * side)[:, None], side


@pytest.fixture(scope="module")
def projection(sphere_atlas, off_surface):
    return closest_point(sphere_atlas, off_surface[1])


def test_projects_onto_the_sphere(projection, off_surface):
    u, x, side = off_surface
    assert projection.converged.all()
    err = np.linalg.norm(projection.point - u, axis=1)
    # measured at N = 1500: median 1.6e-5, max 2.9e-4 (the atlas' own surface error, O(h²))
    assert np.median(err) < 5e-5 and err.max() < 5e-4
    assert np.abs(projection.distance - OFFSET).max() < 5e-4
    cos = np.einsum("ij,ij->i", projection.normal, u)
    np.testing.assert_array_equal(np.sign(cos), side)  # normal points towards x
    assert np.abs(np.abs(cos) - 1.0).max() < 1e-4


def test_projection_is_a_stationary_point_of_the_chosen_chart(sphere_atlas, projection,
                                                              off_surface):
    x = off_surface[1]
    # x = π(x) + distance · n, i.e. x − φ_κ(ξ) is normal to the chart there
    np.testing.assert_allclose(projection.point + projection.distance[:, None]
                               * projection.normal, x, atol=1e-10)
    for k in np.unique(projection.chart)[:5]:
        rows = np.flatnonzero(projection.chart == k)
        X, T, _, out = sphere_atlas.charts_[k].evaluate(projection.xi[rows], order=1)
        assert not out.any()
        np.testing.assert_allclose(X, projection.point[rows], atol=1e-14)
        assert np.abs(np.einsum("mai,mi->ma", T, X - x[rows])).max() < 1e-10


def test_newton_converges_quadratically(sphere_atlas, projection, off_surface):
    assert projection.n_iter.max() <= 6  # measured: 4 or 5 from the nearest control point
    k = int(np.bincount(projection.chart).argmax())
    rows = np.flatnonzero(projection.chart == k)
    chart = sphere_atlas.charts_[k]
    x = off_surface[1][rows]
    _, a = cKDTree(chart.control_points).query(x)
    res = newton_on_chart(chart, x, chart.xi_nodes[a])
    assert res.converged.all()
    steps = np.array(res.history)  # (iterations, m), NaN once a row stopped
    for e0, e1 in zip(steps[:-1], steps[1:]):
        ok = np.isfinite(e0) & np.isfinite(e1) & (e1 > 1e-12)
        # quadratic: |Δξ_{k+1}| ≲ C |Δξ_k|², measured C ≈ 1
        assert np.all(e1[ok] <= 10.0 * e0[ok] ** 2)


def test_samples_project_onto_themselves(sphere_atlas):
    """Each chart interpolates the samples (least-squares fit), so P_a is its own projection
    and π(P_a) = P_a in every chart with ψ_κ(P_a) > 0."""
    P = sphere_atlas.points_[::15]
    proj = closest_point(sphere_atlas, P)
    assert proj.converged.all() and proj.distance.max() < 1e-12
    np.testing.assert_allclose(blended_map(sphere_atlas, P), P, atol=1e-12)


def test_blended_map_lies_on_the_sphere(sphere_atlas, off_surface):
    u, x, _ = off_surface
    rows, _, _ = candidate_pairs(sphere_atlas, u)
    assert np.bincount(rows).max() > 1  # overlaps really blend several charts
    for y in (u, x):
        pi = blended_map(sphere_atlas, y)
        r = np.abs(np.linalg.norm(pi, axis=1) - 1.0)
        assert np.median(r) < 5e-5 and r.max() < 5e-4  # measured 1.6e-5 / 2.8e-4
        assert np.linalg.norm(pi - u, axis=1).max() < 5e-4


def test_far_point_is_outside_every_chart(sphere_atlas):
    x = np.array([[1.0, 1.0, 4.0], [0.0, 0.0, 1.0 + OFFSET]])
    with pytest.raises(InputError, match=r"point 0 at .*outside every chart.*on_failure='flag'"):
        closest_point(sphere_atlas, x)
    with pytest.raises(InputError, match="outside every chart"):
        blended_map(sphere_atlas, x)
    proj = closest_point(sphere_atlas, x, on_failure="flag")
    assert proj.chart[0] == -1 and not proj.converged[0] and np.isnan(proj.point[0]).all()
    assert proj.converged[1] and proj.distance[1] == pytest.approx(OFFSET, abs=5e-4)
    pi = blended_map(sphere_atlas, x, on_failure="flag")
    assert np.isnan(pi[0]).all() and np.linalg.norm(pi[1]) == pytest.approx(1.0, abs=5e-4)


def test_single_chart_and_bad_input(sphere_atlas, projection, off_surface):
    x = off_surface[1]
    k = int(projection.chart[0])
    one = closest_point(sphere_atlas, x[:1], chart=k)
    np.testing.assert_allclose(one.point, projection.point[:1], atol=1e-12)
    with pytest.raises(InputError, match="chart = 999"):
        closest_point(sphere_atlas, x[:1], chart=999)
    with pytest.raises(InputError, match=r"\(m, 3\)"):
        closest_point(sphere_atlas, np.zeros((2, 2)))
    with pytest.raises(InputError, match="on_failure"):
        closest_point(sphere_atlas, x[:1], on_failure="ignore")
